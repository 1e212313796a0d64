// The vectorized noise model against its plain twin (sensors/reference/depth_noise.cpp, the model before the
// rewrite): every float equal bit for bit (NaN included) for every switch, sizes, seeds, special depths, one
// thread or many, and each instruction set this CPU runs.
#include "sensors/depth_noise.hpp"
#include "sensors/reference/depth_noise.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "common/splitmix.hpp"

namespace stvl::sensors {
namespace {

// A depth image with what the model treats specially: steps (edges), a floor-like ramp, near/far range limits,
// and scattered 0, NaN, +Inf, -Inf, negative, denormal and huge depths.
DepthImage scene(int width, int height, uint64_t seed) {
  DepthImage image(width, height);
  const float specials[] = {0.0f,
                            std::numeric_limits<float>::quiet_NaN(),
                            std::numeric_limits<float>::infinity(),
                            -std::numeric_limits<float>::infinity(),
                            -1.5f,
                            1e-40f,
                            1e30f,
                            0.1f,
                            0.2f,
                            30.0f,
                            7.99f,
                            8.0f,
                            -0.0f};
  uint64_t state = seed;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const uint64_t r = splitmix64(state++);
      float z = 1.0f + 0.004f * float(u) + 0.05f * float(v % 17);  // smooth, steeper down the rows
      if ((u / 5 + v / 3) % 4 == 0) z = 0.6f + 0.001f * float(v);  // foreground blocks: steps of 0.4 m or more
      if (u % 23 == 11) z += 3.0f;                                 // thin far columns
      if (r % 29 == 0) z = specials[(r >> 8) % (sizeof(specials) / sizeof(float))];
      image.at(u, v) = z;
    }
  }
  return image;
}

std::vector<uint32_t> bits(const DepthImage& image) {
  std::vector<uint32_t> b(image.depth_m.size());
  std::memcpy(b.data(), image.depth_m.data(), b.size() * sizeof(float));
  return b;
}

// Index of the first pixel whose bits differ (or the size when one image is larger), -1 when equal.
long first_difference(const DepthImage& a, const DepthImage& b) {
  const std::vector<uint32_t> x = bits(a), y = bits(b);
  for (size_t i = 0; i < std::min(x.size(), y.size()); ++i)
    if (x[i] != y[i]) return long(i);
  return x.size() == y.size() ? -1 : long(std::min(x.size(), y.size()));
}

// For failure messages: the pixel and both values there.
std::string at(const DepthImage& a, const DepthImage& b, long i, const DepthImage& truth) {
  if (i < 0 || size_t(i) >= a.depth_m.size() || size_t(i) >= b.depth_m.size()) return "";
  char text[160];
  std::snprintf(text, sizeof(text), " (u %ld, v %ld: %.9g against %.9g, clean %.9g)", i % a.width, i / a.width,
                a.depth_m[size_t(i)], b.depth_m[size_t(i)], truth.depth_m[size_t(i)]);
  return text;
}

using Change = std::function<void(DepthNoiseConfig&)>;

const std::vector<std::pair<std::string, Change>>& configs() {
  static const std::vector<std::pair<std::string, Change>> list = {
      {"defaults", [](DepthNoiseConfig&) {}},
      {"edges off", [](DepthNoiseConfig& c) { c.edge_probability = 0.0; }},
      {"edges always, fly",
       [](DepthNoiseConfig& c) {
         c.edge_probability = 1.0;
         c.edge_invalid_fraction = 0.0;
       }},
      {"edges always, vanish",
       [](DepthNoiseConfig& c) {
         c.edge_probability = 1.0;
         c.edge_invalid_fraction = 1.0;
       }},
      {"edge jump 0", [](DepthNoiseConfig& c) { c.edge_jump_m = 0.0; }},
      {"no dropout", [](DepthNoiseConfig& c) { c.dropout_probability = 0.0; }},
      {"dropout 0.3", [](DepthNoiseConfig& c) { c.dropout_probability = 0.3; }},
      {"dropout 1", [](DepthNoiseConfig& c) { c.dropout_probability = 1.0; }},
      {"holes 5.5 radius 9",
       [](DepthNoiseConfig& c) {
         c.holes_per_frame = 5.5;
         c.hole_max_radius_px = 9.0;
       }},
      {"no holes", [](DepthNoiseConfig& c) { c.holes_per_frame = 0.0; }},
      {"stereo occlusion", [](DepthNoiseConfig& c) { c.stereo_occlusion = true; }},
      {"occlusion, no margins",
       [](DepthNoiseConfig& c) {
         c.stereo_occlusion = true;
         c.left_band_margin_px = 0.0;
         c.left_band_jitter_px = 0.0;
         c.shadow_margin_px = 0.0;
       }},
      {"correlated 0.95 cell 12", [](DepthNoiseConfig& c) { c.correlated_fraction = 0.95; }},
      {"correlated 0.5 cell 1",
       [](DepthNoiseConfig& c) {
         c.correlated_fraction = 0.5;
         c.correlated_cell_px = 1.0;
       }},
      {"correlated 1 cell 7",
       [](DepthNoiseConfig& c) {
         c.correlated_fraction = 1.0;
         c.correlated_cell_px = 7.0;
       }},
      {"step 0", [](DepthNoiseConfig& c) { c.disparity_step_px = 0.0; }},
      {"step 1 px", [](DepthNoiseConfig& c) { c.disparity_step_px = 1.0; }},
      {"step 1e-6 px", [](DepthNoiseConfig& c) { c.disparity_step_px = 1e-6; }},
      {"step 1e-9 px (plain path)", [](DepthNoiseConfig& c) { c.disparity_step_px = 1e-9; }},
      {"subpixel 0", [](DepthNoiseConfig& c) { c.subpixel = 0.0; }},
      {"subpixel 0, step 0",
       [](DepthNoiseConfig& c) {
         c.subpixel = 0.0;
         c.disparity_step_px = 0.0;
       }},
      {"subpixel 3, correlated",
       [](DepthNoiseConfig& c) {
         c.subpixel = 3.0;
         c.correlated_fraction = 0.9;
       }},
      {"all off",
       [](DepthNoiseConfig& c) {
         c.subpixel = 0.0;
         c.disparity_step_px = 0.0;
         c.edge_probability = 0.0;
         c.dropout_probability = 0.0;
         c.holes_per_frame = 0.0;
       }},
      {"everything on",
       [](DepthNoiseConfig& c) {
         c.stereo_occlusion = true;
         c.correlated_fraction = 0.9;
         c.correlated_cell_px = 5.0;
         c.dropout_probability = 0.05;
         c.edge_probability = 0.7;
         c.holes_per_frame = 3.3;
       }},
      {"disabled", [](DepthNoiseConfig& c) { c.enabled = false; }},
  };
  return list;
}

std::vector<NoiseSimd> simd_levels() {
  std::vector<NoiseSimd> levels;
  const NoiseSimd best = DepthNoise(DepthNoiseConfig{}, CameraIntrinsics::d435_640x480()).simd();
  for (NoiseSimd s : {NoiseSimd::kBaseline, NoiseSimd::kAvx2, NoiseSimd::kAvx512})
    if (s <= best) levels.push_back(s);
  return levels;
}

const char* name(NoiseSimd s) {
  return s == NoiseSimd::kAvx512 ? "avx512" : s == NoiseSimd::kAvx2 ? "avx2" : "baseline";
}

// Every config, size, seed, frame, instruction set and thread split: in place and clean -> noisy, as the reference.
TEST(DepthNoiseAgainstReference, EveryConfigSizeSeedAndInstructionSet) {
  const std::vector<std::pair<int, int>> sizes = {{7, 5}, {641, 3}, {1, 1}, {1, 9}, {13, 1}, {101, 37}, {1030, 4}};
  const std::vector<std::pair<uint64_t, uint64_t>> seeds_frames = {{1, 0}, {7, 3}, {123456789, 99}};
  const std::vector<NoiseSimd> levels = simd_levels();
  long compared = 0, cases = 0, changed = 0;
  for (const auto& [config_name, change] : configs()) {
    DepthNoiseConfig config;
    change(config);
    for (const auto& [W, H] : sizes) {
      const CameraIntrinsics k = CameraIntrinsics::from_hfov(W, H, 1.2, 0.2, 8.0, 30.0);
      reference::DepthNoise plain(config, k);
      DepthNoise noise(config, k);
      for (const auto& [seed, frame] : seeds_frames) {
        const DepthImage truth = scene(W, H, seed * 31 + frame);
        DepthImage expected = truth;
        plain.apply(expected, seed, frame, /*parallel=*/false);
        changed += first_difference(expected, truth) >= 0;
        ++cases;
        for (NoiseSimd simd : levels) {
          noise.limit_simd(simd);
          ASSERT_EQ(noise.simd(), simd);
          for (bool parallel : {false, true}) {
            const std::string what = config_name + ", " + std::to_string(W) + "x" + std::to_string(H) + ", seed " +
                                     std::to_string(seed) + " frame " + std::to_string(frame) + ", " + name(simd) +
                                     (parallel ? ", parallel" : ", one thread");
            DepthImage in_place = truth;
            noise.apply(in_place, seed, frame, parallel);
            const long d_in_place = first_difference(in_place, expected);
            EXPECT_EQ(d_in_place, -1) << what << ", in place" << at(in_place, expected, d_in_place, truth);
            DepthImage noisy(3, 2);  // wrong size on purpose: resized
            noise.apply(truth, noisy, seed, frame, parallel);
            EXPECT_EQ(noisy.width, W);
            EXPECT_EQ(noisy.height, H);
            const long d_noisy = first_difference(noisy, expected);
            EXPECT_EQ(d_noisy, -1) << what << ", clean -> noisy" << at(noisy, expected, d_noisy, truth);
            compared += 2;
          }
        }
      }
    }
  }
  EXPECT_GT(changed, cases * 3 / 4);  // the noise did change most images
  std::printf("%ld images compared over %zu instruction sets\n", compared, levels.size());
}

// A full-size frame at the defaults: every one of the 407,040 floats, over several frames.
TEST(DepthNoiseAgainstReference, FullSizeFramesAtTheDefaults) {
  const CameraIntrinsics k = CameraIntrinsics::d435_848x480();
  reference::DepthNoise plain(DepthNoiseConfig{}, k);
  DepthNoise noise(DepthNoiseConfig{}, k);
  for (uint64_t frame = 0; frame < 4; ++frame) {
    const DepthImage truth = scene(k.width, k.height, frame);
    DepthImage expected = truth, noisy;
    plain.apply(expected, 42, frame);
    noise.apply(truth, noisy, 42, frame);
    EXPECT_EQ(first_difference(noisy, expected), -1) << "frame " << frame;
  }
}

// The comparison can fail: another seed, frame or config gives other bits, and one flipped bit is found.
TEST(DepthNoiseAgainstReference, ComparisonSeesDifferences) {
  const CameraIntrinsics k = CameraIntrinsics::from_hfov(101, 37, 1.2, 0.2, 8.0, 30.0);
  const DepthImage truth = scene(k.width, k.height, 5);
  DepthImage a = truth, b = truth, c = truth;
  DepthNoise(DepthNoiseConfig{}, k).apply(a, 1, 2);
  reference::DepthNoise(DepthNoiseConfig{}, k).apply(b, 1, 3);
  EXPECT_GE(first_difference(a, b), 0);
  DepthNoiseConfig coarse;
  coarse.disparity_step_px = 1.0 / 16.0;
  reference::DepthNoise(coarse, k).apply(c, 1, 2);
  EXPECT_GE(first_difference(a, c), 0);
  DepthImage d = a;
  uint32_t word;
  std::memcpy(&word, &d.depth_m[777], 4);
  word ^= 1u;
  std::memcpy(&d.depth_m[777], &word, 4);
  EXPECT_EQ(first_difference(a, d), 777);
  DepthImage nan_a = a, nan_b = a;  // NaN payloads compare by bits
  nan_a.depth_m[5] = std::numeric_limits<float>::quiet_NaN();
  nan_b.depth_m[5] = -std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(first_difference(nan_a, nan_b), 5);
}

TEST(DepthNoiseAgainstReference, CleanToNoisyChecksSizeAndAcceptsTheSameImage) {
  const CameraIntrinsics k = CameraIntrinsics::from_hfov(31, 7, 1.2, 0.2, 8.0, 30.0);
  DepthNoise noise(DepthNoiseConfig{}, k);
  DepthImage wrong(30, 7), out;
  EXPECT_THROW(noise.apply(wrong, out, 1, 1), std::invalid_argument);
  DepthImage same = scene(k.width, k.height, 3), expected = same;
  noise.apply(same, same, 1, 1);
  reference::DepthNoise(DepthNoiseConfig{}, k).apply(expected, 1, 1);
  EXPECT_EQ(first_difference(same, expected), -1);
}

}  // namespace
}  // namespace stvl::sensors

#include "sensors/depth_noise.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace stvl::sensors {
namespace {

constexpr double kRmsTolerance = 0.20;  // measured std vs Intel's formula

DepthImage flat_wall(const CameraIntrinsics& k, float z_m) {
  DepthImage image(k.width, k.height);
  std::fill(image.depth_m.begin(), image.depth_m.end(), z_m);
  return image;
}

DepthNoiseConfig stereo_only() {
  DepthNoiseConfig config;
  config.edge_probability = 0.0;
  config.dropout_probability = 0.0;
  config.holes_per_frame = 0.0;
  return config;
}

class NoiseRms : public ::testing::TestWithParam<double> {};

TEST_P(NoiseRms, StdOfDepthErrorMatchesIntelFormula) {
  const double z = GetParam();
  const CameraIntrinsics k = CameraIntrinsics::d435_848x480();
  DepthNoise noise(stereo_only(), k);  // quantization (1/32 px) stays on and is part of the measured std
  DepthImage image = flat_wall(k, float(z));
  noise.apply(image, 42, 0);
  double sum = 0.0, sum_sq = 0.0;
  int n = 0;
  for (float d : image.depth_m) {
    ASSERT_GT(d, 0.0f);
    const double error = d - z;
    sum += error;
    sum_sq += error * error;
    ++n;
  }
  const double mean = sum / n;
  const double std = std::sqrt(sum_sq / n - mean * mean);
  const double expected = noise.rms_error_m(z);
  std::printf("z %.1f m: measured std %.3f mm, formula %.3f mm, ratio %.3f, mean %.3f mm\n", z, 1e3 * std,
              1e3 * expected, std / expected, 1e3 * mean);
  EXPECT_NEAR(expected, z * z * 0.08 / (k.fx * 0.05), 1e-12);
  EXPECT_NEAR(std / expected, 1.0, kRmsTolerance) << "z " << z << " std " << std << " expected " << expected;
  EXPECT_LT(std::abs(mean), 0.2 * expected);  // first-order unbiased
}

INSTANTIATE_TEST_SUITE_P(FlatWall, NoiseRms, ::testing::Values(1.0, 3.0));

TEST(DepthNoise, DeterministicPerSeedAndFrame) {
  const CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  DepthNoise noise(DepthNoiseConfig{}, k);
  const DepthImage truth = flat_wall(k, 2.0f);
  auto noisy = [&](uint64_t seed, uint64_t frame) {
    DepthImage image = truth;
    noise.apply(image, seed, frame);
    return image.depth_m;
  };
  EXPECT_EQ(noisy(7, 3), noisy(7, 3));
  EXPECT_NE(noisy(7, 3), noisy(8, 3));
  EXPECT_NE(noisy(7, 3), noisy(7, 4));
  DepthNoise other(DepthNoiseConfig{}, k);  // a second instance, after other frames, gives the same frame
  DepthImage image = truth;
  other.apply(image, 7, 3);
  EXPECT_EQ(image.depth_m, noisy(7, 3));
}

// Rows run in parallel: the image must equal the one-pass reference however they are split (an odd width puts block
// starts in the middle of a four-pixel group of normal draws; a step in depth makes edge pixels).
TEST(DepthNoise, SameImageOnOneThreadAndOnMany) {
  const CameraIntrinsics k = CameraIntrinsics::from_hfov(101, 37, 1.2, 0.2, 8.0, 30.0);
  DepthImage truth = flat_wall(k, 2.0f);
  for (int v = 0; v < k.height; ++v)
    for (int u = k.width / 2; u < k.width; ++u) truth.at(u, v) = 3.5f;
  DepthNoise noise(DepthNoiseConfig{}, k);
  const auto noisy = [&](bool parallel) {
    DepthImage image = truth;
    noise.apply(image, 11, 5, parallel);
    return image.depth_m;
  };
  const std::vector<float> reference = noisy(false);  // one pass over all rows
  for (int repeat = 0; repeat < 5; ++repeat) EXPECT_EQ(noisy(true), reference);
  {
    const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    EXPECT_EQ(noisy(true), reference);
  }
  EXPECT_NE(reference, truth.depth_m);
}

TEST(DepthNoise, DisabledIsIdentity) {
  const CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  DepthNoiseConfig config;
  config.enabled = false;
  DepthNoise noise(config, k);
  DepthImage image = flat_wall(k, 2.0f);
  noise.apply(image, 1, 1);
  EXPECT_EQ(image.depth_m, flat_wall(k, 2.0f).depth_m);
}

TEST(DepthNoise, RangeInvalidation) {
  const CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  DepthNoise noise(stereo_only(), k);
  for (float z : {0.1f, 12.0f}) {
    DepthImage image = flat_wall(k, z);
    noise.apply(image, 1, 0);
    EXPECT_EQ(image.valid_count(), 0) << z;
  }
}

TEST(DepthNoise, DropoutsAndHoles) {
  const CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  DepthNoiseConfig config = stereo_only();
  config.subpixel = 0.0;
  config.disparity_step_px = 0.0;
  config.dropout_probability = 0.01;
  DepthNoise dropouts(config, k);
  DepthImage image = flat_wall(k, 2.0f);
  dropouts.apply(image, 5, 0);
  const double n = double(k.width) * k.height;
  const double dropped = (n - image.valid_count()) / n;
  EXPECT_NEAR(dropped, 0.01, 0.001);

  config.dropout_probability = 0.0;
  config.holes_per_frame = 3.0;
  config.hole_max_radius_px = 6.0;
  DepthNoise holes(config, k);
  image = flat_wall(k, 2.0f);
  holes.apply(image, 5, 0);
  const int missing = int(n) - image.valid_count();
  EXPECT_GT(missing, 0);
  EXPECT_LE(missing, 3 * int(std::ceil(M_PI * 7.0 * 7.0)));
  // Missing pixels come in blobs: most have a missing 4-neighbour.
  int clustered = 0;
  for (int v = 1; v + 1 < k.height; ++v) {
    for (int u = 1; u + 1 < k.width; ++u) {
      if (image.at(u, v) != 0.0f) continue;
      clustered += (image.at(u - 1, v) == 0.0f || image.at(u + 1, v) == 0.0f || image.at(u, v - 1) == 0.0f ||
                    image.at(u, v + 1) == 0.0f);
    }
  }
  EXPECT_GT(clustered, missing / 2);
}

TEST(DepthNoise, EdgePixelsFlyOrVanishOnlyAtDiscontinuities) {
  const CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  DepthNoiseConfig config = stereo_only();
  config.subpixel = 0.0;
  config.disparity_step_px = 0.0;
  config.edge_probability = 1.0;
  config.edge_invalid_fraction = 0.5;
  DepthNoise noise(config, k);
  DepthImage image(k.width, k.height);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) image.at(u, v) = u < 320 ? 1.0f : 3.0f;
  }
  noise.apply(image, 9, 0);
  int invalid = 0, flying = 0;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const float z = image.at(u, v);
      if (u != 319 && u != 320) {
        ASSERT_EQ(z, u < 320 ? 1.0f : 3.0f) << u << "," << v;
        continue;
      }
      if (z == 0.0f) {
        ++invalid;
      } else {
        EXPECT_GE(z, 1.0f);
        EXPECT_LE(z, 3.0f);
        flying += (z > 1.0f && z < 3.0f);
      }
    }
  }
  EXPECT_NEAR(invalid, 480, 100);  // half of the 960 edge pixels
  EXPECT_GT(flying, 400);
}

TEST(DepthNoise, BadConfigAndSizeThrow) {
  const CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  DepthNoiseConfig config;
  config.dropout_probability = 1.5;
  EXPECT_THROW(DepthNoise(config, k), std::invalid_argument);
  config = DepthNoiseConfig{};
  config.baseline_m = 0.0;
  EXPECT_THROW(DepthNoise(config, k), std::invalid_argument);
  config = DepthNoiseConfig{};
  config.subpixel = -1.0;
  EXPECT_THROW(DepthNoise(config, k), std::invalid_argument);
  DepthNoise noise(DepthNoiseConfig{}, k);
  DepthImage wrong(4, 4);
  EXPECT_THROW(noise.apply(wrong, 1, 1), std::invalid_argument);
}

// ---- Stereo occlusion (DepthNoiseConfig::stereo_occlusion): the real D435's left band and shadows. ----

// Only the occlusion mask: no stereo noise, no other artifacts.
DepthNoiseConfig occlusion_only(double band_margin_px, double jitter_px, double shadow_margin_px) {
  DepthNoiseConfig config = stereo_only();
  config.subpixel = 0.0;
  config.disparity_step_px = 0.0;
  config.stereo_occlusion = true;
  config.left_band_margin_px = band_margin_px;
  config.left_band_jitter_px = jitter_px;
  config.shadow_margin_px = shadow_margin_px;
  return config;
}

int leading_invalid(const DepthImage& image, int v) {
  int u = 0;
  while (u < image.width && image.at(u, v) == 0.0f) ++u;
  return u;
}

// Pixel u lands at column u - fx * b / z of the right image; invalid when that is left of margin - 0.5, so the
// band is ceil(fx * b / z + margin - 0.5) px wide in every row.
TEST(StereoOcclusion, LeftBandWidthFollowsBaselineAndDepth) {
  const CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  for (double margin : {0.0, 12.0}) {
    for (float z : {0.8f, 1.0f, 2.0f, 4.0f}) {
      DepthNoise noise(occlusion_only(margin, 0.0, 0.0), k);
      DepthImage image = flat_wall(k, z);
      noise.apply(image, 1, 0);
      const int expected = int(std::ceil(k.fx * 0.05 / z + margin - 0.5));
      for (int v = 0; v < k.height; v += 37)
        EXPECT_EQ(leading_invalid(image, v), expected) << "z " << z << " row " << v;
      EXPECT_EQ(image.valid_count(), (k.width - expected) * k.height) << "only the band is invalid, z " << z;
    }
  }
  // 1 m, no margin: fx * b / z = 19.5 px -> 20 columns (0 to 19).
  DepthNoise noise(occlusion_only(0.0, 0.0, 0.0), k);
  DepthImage image = flat_wall(k, 1.0f);
  noise.apply(image, 1, 0);
  EXPECT_EQ(leading_invalid(image, 100), 20);
}

TEST(StereoOcclusion, BandJitterIsSeededPerRowAndFrame) {
  const CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  DepthNoise noise(occlusion_only(12.0, 2.0, 0.0), k);
  const auto bands = [&](uint64_t seed, uint64_t frame) {
    DepthImage image = flat_wall(k, 1.7f);
    noise.apply(image, seed, frame);
    std::vector<int> widths;
    for (int v = 0; v < k.height; ++v) widths.push_back(leading_invalid(image, v));
    return widths;
  };
  const std::vector<int> a = bands(3, 0);
  const double d = k.fx * 0.05 / 1.7;
  int lo = k.width, hi = 0;
  for (int w : a) {
    lo = std::min(lo, w);
    hi = std::max(hi, w);
    EXPECT_GE(w, int(std::ceil(d + 12.0 - 2.0 - 0.5)));
    EXPECT_LE(w, int(std::ceil(d + 12.0 + 2.0 - 0.5)));
  }
  EXPECT_GE(hi - lo, 3);  // uniform over 4 px: every row the same would be a bug
  EXPECT_EQ(bands(3, 0), a);
  EXPECT_NE(bands(3, 1), a);
  EXPECT_NE(bands(4, 0), a);
}

// A foreground block at 1 m (columns 300 to 379) before a wall at 2 m: the right imager, 5 cm to the right, sees
// the block shifted left by fx * b / 1 = 19.5 px and the wall by 9.8 px, so the wall's pixels u with
// u - 9.8 >= 300 - 19.5 (u >= 290.7: 291 to 299) are hidden; on the block's right the wall stays visible.
TEST(StereoOcclusion, ShadowLeftOfForegroundEdges) {
  const CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  DepthImage truth = flat_wall(k, 2.0f);
  for (int v = 0; v < k.height; ++v)
    for (int u = 300; u < 380; ++u) truth.at(u, v) = 1.0f;
  const double d_fg = k.fx * 0.05 / 1.0, d_bg = k.fx * 0.05 / 2.0;
  const int first_hidden = int(std::ceil(300 - d_fg + d_bg));
  ASSERT_EQ(first_hidden, 291);
  for (int margin : {0, 6}) {
    DepthNoise noise(occlusion_only(0.0, 0.0, margin), k);
    DepthImage image = truth;
    noise.apply(image, 1, 0);
    for (int v = 0; v < k.height; v += 53) {
      for (int u = 200; u < 460; ++u) {
        const bool hidden = u >= first_hidden - margin && u < 300;
        EXPECT_EQ(image.at(u, v) == 0.0f, hidden) << "u " << u << " v " << v << " margin " << margin;
      }
    }
  }
}

TEST(StereoOcclusion, SameSeedSameImageOnOneThreadAndOnMany) {
  const CameraIntrinsics k = CameraIntrinsics::from_hfov(101, 37, 1.2, 0.2, 8.0, 30.0);
  DepthImage truth = flat_wall(k, 2.0f);
  for (int v = 0; v < k.height; ++v)
    for (int u = 60; u < 80; ++u) truth.at(u, v) = 0.6f;
  DepthNoiseConfig config;
  config.stereo_occlusion = true;
  DepthNoise noise(config, k);
  const auto noisy = [&](bool parallel, uint64_t seed) {
    DepthImage image = truth;
    noise.apply(image, seed, 5, parallel);
    return image.depth_m;
  };
  const std::vector<float> reference = noisy(false, 11);
  EXPECT_EQ(noisy(true, 11), reference);
  EXPECT_EQ(noisy(true, 11), noisy(true, 11));
  EXPECT_NE(noisy(true, 12), reference);
  DepthNoiseConfig off = config;
  off.stereo_occlusion = false;
  DepthImage without = truth;
  DepthNoise(off, k).apply(without, 11, 5);
  EXPECT_GT(std::count(reference.begin(), reference.end(), 0.0f),
            std::count(without.depth_m.begin(), without.depth_m.end(), 0.0f) + 10 * k.height);
}

// With the new switches off the model is the one before them, bit for bit: the FNV-1a hash of this image's floats
// as computed by the model of commit 758bf7c (before stereo_occlusion existed), built separately.
TEST(StereoOcclusion, OffIsBitIdenticalToTheModelBefore) {
  const CameraIntrinsics k = CameraIntrinsics::from_hfov(97, 41, 1.2, 0.2, 8.0, 30.0);
  DepthImage image(k.width, k.height);
  for (int v = 0; v < k.height; ++v)
    for (int u = 0; u < k.width; ++u) image.at(u, v) = (u > 40 && u < 60 && v > 10) ? 1.2f : 2.0f + 0.01f * float(u);
  DepthNoiseConfig config;
  config.holes_per_frame = 3.0;
  config.dropout_probability = 0.01;
  ASSERT_FALSE(config.stereo_occlusion);  // off by default
  DepthNoise(config, k).apply(image, 123, 4, false);
  uint64_t hash = 1469598103934665603ULL;
  for (float f : image.depth_m) {
    uint32_t bits;
    std::memcpy(&bits, &f, 4);
    for (int i = 0; i < 4; ++i) {
      hash ^= (bits >> (8 * i)) & 255u;
      hash *= 1099511628211ULL;
    }
  }
  EXPECT_EQ(hash, 6866128612431820113ULL);
  EXPECT_EQ(image.valid_count(), 3786);
}

TEST(StereoOcclusion, BadMarginsThrow) {
  const CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  for (auto change : {+[](DepthNoiseConfig& c) { c.left_band_margin_px = -1.0; },
                      +[](DepthNoiseConfig& c) { c.left_band_jitter_px = std::nan(""); },
                      +[](DepthNoiseConfig& c) { c.shadow_margin_px = 1e9; }}) {
    DepthNoiseConfig config;
    change(config);
    EXPECT_THROW(DepthNoise(config, k), std::invalid_argument);
  }
}

}  // namespace
}  // namespace stvl::sensors

namespace stvl::sensors {
namespace {

// correlated_fraction: the disparity noise becomes (mostly) a smooth field; each pixel's total stays Intel's formula.
TEST(CorrelatedNoise, KeepsIntelsRmsAndCorrelatesNeighbours) {
  const CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  const auto stats = [&](double fraction, uint64_t seed, double* lag1, double* lag32) {
    DepthNoiseConfig config = stereo_only();
    config.correlated_fraction = fraction;
    config.correlated_cell_px = 16.0;
    DepthNoise noise(config, k);
    DepthImage image = flat_wall(k, 2.0f);
    noise.apply(image, seed, 0);
    double sum_sq = 0.0, c1 = 0.0, c32 = 0.0;
    for (int v = 0; v < k.height; ++v)
      for (int u = 0; u < k.width; ++u) {
        const double e = image.at(u, v) - 2.0;
        sum_sq += e * e;
        if (u + 1 < k.width) c1 += e * (image.at(u + 1, v) - 2.0);
        if (u + 32 < k.width) c32 += e * (image.at(u + 32, v) - 2.0);
      }
    const double n = double(k.width) * k.height;
    *lag1 = c1 / sum_sq;
    *lag32 = c32 / sum_sq;
    return std::sqrt(sum_sq / n) / noise.rms_error_m(2.0);
  };
  double lag1 = 0, lag32 = 0;
  // A 16 px grid gives about 40 x 30 independent values per frame: the frame's RMS scatters by about 5 %.
  double ratio = 0;
  for (uint64_t seed = 1; seed <= 4; ++seed) ratio += stats(0.95, seed, &lag1, &lag32) / 4;
  EXPECT_NEAR(ratio, 1.0, 0.08);
  EXPECT_GT(lag1, 0.85);             // 0.93 expected: sqrt(0.95)^2 of the field (~0.98 between neighbours) + white 0.05
  EXPECT_LT(std::abs(lag32), 0.15);  // beyond two cells: independent
  EXPECT_NEAR(stats(0.0, 1, &lag1, &lag32), 1.0, kRmsTolerance);
  EXPECT_LT(std::abs(lag1), 0.05);  // white noise: no correlation
}

TEST(CorrelatedNoise, SeededAndSameOnOneThreadAndOnMany) {
  const CameraIntrinsics k = CameraIntrinsics::from_hfov(101, 37, 1.2, 0.2, 8.0, 30.0);
  DepthNoiseConfig config;
  config.correlated_fraction = 0.9;
  config.correlated_cell_px = 7.0;
  DepthNoise noise(config, k);
  const auto noisy = [&](bool parallel, uint64_t seed, uint64_t frame) {
    DepthImage image = flat_wall(k, 2.0f);
    noise.apply(image, seed, frame, parallel);
    return image.depth_m;
  };
  const std::vector<float> reference = noisy(false, 3, 2);
  EXPECT_EQ(noisy(true, 3, 2), reference);
  EXPECT_NE(noisy(true, 3, 3), reference);
  EXPECT_NE(noisy(true, 4, 2), reference);
  DepthNoiseConfig bad;
  bad.correlated_fraction = 1.5;
  EXPECT_THROW(DepthNoise(bad, k), std::invalid_argument);
  bad = DepthNoiseConfig{};
  bad.correlated_cell_px = 0.5;
  EXPECT_THROW(DepthNoise(bad, k), std::invalid_argument);
}

}  // namespace
}  // namespace stvl::sensors

// Speed of the vectorized noise model against its plain twin (the model before the rewrite), interleaved in one
// process on the same frames. Disabled by default (a benchmark, not a check); run it with
//   build/bin/test_sensors --gtest_also_run_disabled_tests --gtest_filter='DepthNoiseSpeed.*'
// STVL_NOISE_SPEED_ROUNDS (default 15) sets the number of interleaved rounds.
#include "sensors/depth_noise.hpp"
#include "sensors/reference/depth_noise.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <vector>

#include <Eigen/Geometry>

namespace stvl::sensors {
namespace {

// Depth along the optical axis of a ray (z = 1 scaled) from `origin` to the first of these boxes' faces: a 3 m
// wide, 2.6 m high corridor seen from inside, and obstacles seen from outside (as sensors-bench's world).
struct Box {
  Eigen::Vector3d lo, hi;
};
const Box kObstacles[] = {{{1.7, 0.5, 0.0}, {2.3, 1.1, 0.8}},      {{3.3, -0.9, 0.0}, {3.7, -0.5, 1.0}},
                          {{4.75, -0.05, 0.0}, {5.25, 0.45, 0.5}}, {{6.5, -1.2, 0.0}, {7.5, -0.8, 1.8}},
                          {{8.95, 0.85, 0.0}, {9.05, 0.95, 2.6}},  {{11.6, -0.4, 0.0}, {12.4, 0.4, 0.8}}};

double hit_depth(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir_world) {
  double t_best = std::numeric_limits<double>::infinity();
  for (const Box& b : kObstacles) {  // slab test from outside
    double t0 = 0.0, t1 = t_best;
    for (int a = 0; a < 3; ++a) {
      const double ta = (b.lo[a] - origin[a]) / dir_world[a], tb = (b.hi[a] - origin[a]) / dir_world[a];
      t0 = std::max(t0, std::min(ta, tb));
      t1 = std::min(t1, std::max(ta, tb));
    }
    if (t0 < t1) t_best = t0;
  }
  const Eigen::Vector3d room_lo(-4.0, -1.5, 0.0), room_hi(19.0, 1.5, 2.6);  // from inside: the nearest exit face
  for (int a = 0; a < 3; ++a) {
    const double wall = dir_world[a] > 0 ? room_hi[a] : room_lo[a];
    const double t = (wall - origin[a]) / dir_world[a];
    if (t > 0.0) t_best = std::min(t_best, t);
  }
  return t_best;
}

std::vector<DepthImage> corridor_frames(const CameraIntrinsics& k, int count) {
  std::vector<DepthImage> frames;
  Eigen::Matrix3d optical_to_body;  // optical z forward = body x, x right = -y, y down = -z
  optical_to_body << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  for (int i = 0; i < count; ++i) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.17 * std::sin(0.5 * i), Eigen::Vector3d::UnitZ()) * optical_to_body;
    const Eigen::Vector3d origin(0.3 * i, 0.0, 0.4);
    DepthImage image(k.width, k.height);
    for (int v = 0; v < k.height; ++v)
      for (int u = 0; u < k.width; ++u) {
        const double z = hit_depth(origin, R * pixel_ray_C(k, u, v));  // the ray has z = 1: t is the depth
        image.at(u, v) = std::isfinite(z) ? float(z) : 0.0f;
      }
    frames.push_back(std::move(image));
  }
  return frames;
}

double median(std::vector<double> x) {
  std::sort(x.begin(), x.end());
  return x[x.size() / 2];
}

TEST(DepthNoiseSpeed, DISABLED_ReferenceAgainstVectorizedInterleaved) {
  const char* rounds_env = std::getenv("STVL_NOISE_SPEED_ROUNDS");
  const int rounds = rounds_env ? std::max(1, std::atoi(rounds_env)) : 15;
  using clock = std::chrono::steady_clock;
  const auto ms = [](clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); };
  for (const CameraIntrinsics& k : {CameraIntrinsics::d435_848x480(), CameraIntrinsics::d435_640x480()}) {
    const std::vector<DepthImage> frames = corridor_frames(k, 8);
    for (bool parallel : {true, false}) {
      reference::DepthNoise plain(DepthNoiseConfig{}, k);
      DepthNoise noise(DepthNoiseConfig{}, k);
      // Per round and frame: the reference in place after the pipeline's copy (as pipeline.cpp did), then the
      // vectorized model clean -> noisy (as it does now), then in place after a copy; order alternates.
      std::vector<double> t_ref, t_new, t_new_in_place, ratio;
      DepthImage a, b, c;
      for (int r = 0; r < rounds; ++r) {
        double ref_ms = 0, new_ms = 0, in_place_ms = 0;
        for (size_t i = 0; i < frames.size(); ++i) {
          const uint64_t frame = uint64_t(r) * frames.size() + i;
          const auto run_ref = [&] {
            const auto t0 = clock::now();
            a = frames[i];
            plain.apply(a, 7, frame, parallel);
            ref_ms += ms(clock::now() - t0);
          };
          const auto run_new = [&] {
            const auto t0 = clock::now();
            noise.apply(frames[i], b, 7, frame, parallel);
            new_ms += ms(clock::now() - t0);
            const auto t1 = clock::now();
            c = frames[i];
            noise.apply(c, 7, frame, parallel);
            in_place_ms += ms(clock::now() - t1);
          };
          if ((r + i) % 2 == 0) {
            run_ref();
            run_new();
          } else {
            run_new();
            run_ref();
          }
          ASSERT_EQ(a.depth_m.size(), b.depth_m.size());
          ASSERT_EQ(0, std::memcmp(a.depth_m.data(), b.depth_m.data(), a.depth_m.size() * sizeof(float)));
          ASSERT_EQ(0, std::memcmp(a.depth_m.data(), c.depth_m.data(), a.depth_m.size() * sizeof(float)));
        }
        t_ref.push_back(ref_ms / frames.size());
        t_new.push_back(new_ms / frames.size());
        t_new_in_place.push_back(in_place_ms / frames.size());
        ratio.push_back(ref_ms / new_ms);
      }
      std::printf(
          "%dx%d %-10s reference %.3f ms, vectorized clean->noisy %.3f ms (in place %.3f ms); "
          "reference / vectorized: median %.2fx (min %.2fx, max %.2fx) over %d rounds of %zu frames\n",
          k.width, k.height, parallel ? "parallel" : "one thread", median(t_ref), median(t_new), median(t_new_in_place),
          median(ratio), *std::min_element(ratio.begin(), ratio.end()), *std::max_element(ratio.begin(), ratio.end()),
          rounds, frames.size());
    }
  }
}

}  // namespace
}  // namespace stvl::sensors

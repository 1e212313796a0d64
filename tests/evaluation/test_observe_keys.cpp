// observed_keys (evaluation/observe_keys.hpp: row blocks in parallel, each row branch-free, neighbours skipped)
// against the plain per-pixel loop, on depth images smooth (planes, where neighbours share voxels) and rough
// (random depths, holes, NaN and Inf), at several sizes, poses, ranges and bands.
#include "evaluation/observe_keys.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "evaluation/reference/observe_keys.hpp"

namespace stvl::evaluation {
namespace {

sensors::DepthImage image(int width, int height, std::mt19937& rng, bool smooth) {
  sensors::DepthImage d(width, height);
  std::uniform_real_distribution<float> depth(0.1f, 12.0f), unit(0.0f, 1.0f);
  const float a = 1.0f + 3.0f * unit(rng), bu = 0.01f * (unit(rng) - 0.5f), bv = 0.02f * unit(rng);
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      float z = smooth ? a + bu * u + bv * v : depth(rng);
      const float special = unit(rng);
      if (special < 0.05f) z = 0.0f;  // no return
      if (special > 0.995f) z = std::numeric_limits<float>::quiet_NaN();
      if (special > 0.998f) z = std::numeric_limits<float>::infinity();
      d.depth_m[static_cast<std::size_t>(v) * width + u] = z;
    }
  return d;
}

TEST(ObserveKeys, EqualsThePerPixelLoop) {
  std::mt19937 rng(44);
  std::uniform_real_distribution<double> angle(-3.0, 3.0), offset(-20.0, 20.0);
  int nonempty = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const int width = trial % 4 == 0 ? 848 : 31 + 37 * (trial % 7),
              height = trial % 4 == 0 ? 480 : 17 + 29 * (trial % 5);
    sensors::CameraIntrinsics k = sensors::CameraIntrinsics::d435_848x480();
    k.width = width, k.height = height, k.cx = 0.5 * width - 0.3, k.cy = 0.5 * height + 0.7;
    const sensors::DepthImage depth = image(width, height, rng, trial % 2 == 0);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = (Eigen::AngleAxisd(angle(rng), Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(angle(rng), Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
    T.translation() = Eigen::Vector3d(offset(rng), offset(rng), 0.1 * offset(rng));
    EvaluationConfig config;
    config.voxel_size_m = trial % 3 == 0 ? 0.05 : 0.1 + 0.01 * trial;
    config.min_obstacle_height_m = trial % 5 == 0 ? -1e9 : -2.0 + 0.1 * trial;
    config.max_obstacle_height_m = config.min_obstacle_height_m + (trial % 5 == 0 ? 2e9 : 3.0);
    const double range_m = trial % 6 == 0 ? std::numeric_limits<double>::infinity() : 1.0 + 0.3 * trial;
    std::vector<VoxelKey> fast, plain;
    observed_keys(depth, k, T, range_m, config, fast);
    reference::observed_keys(depth, k, T, range_m, config, plain);
    EXPECT_EQ(fast, plain) << "trial " << trial;
    nonempty += !plain.empty();
  }
  EXPECT_GE(nonempty, 20);  // the bands and ranges leave half the images or more something to see (29 of 40)
}

}  // namespace
}  // namespace stvl::evaluation

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "bench/synthetic_corridor.hpp"

namespace stvl::bench {
namespace {

constexpr double kExact = 1e-12;
constexpr float kNoiseMarginM = 0.2f;  // sigma = 1 mm * depth^2: well under 0.2 m within 10 m

TEST(SyntheticCorridor, RaysHitWallsFloorCeilingAndBoxes) {
  const Eigen::Vector3d centre(0.0, 1.0, 1.0);
  EXPECT_NEAR(cast_corridor_ray(centre, {0, 0, -1}), 1.0, kExact);            // floor
  EXPECT_NEAR(cast_corridor_ray(centre, {0, 0, 2}), 0.75, kExact);            // ceiling at 2.5 m, direction of length 2
  EXPECT_NEAR(cast_corridor_ray(centre, {-1, 0, 0}), 1.0, kExact);            // left wall
  EXPECT_NEAR(cast_corridor_ray(centre, {1, 0, 0}), 1.0, kExact);             // right wall
  EXPECT_NEAR(cast_corridor_ray(centre, {0, 1, 0}), 29.0, kExact);            // end wall at 30 m
  EXPECT_NEAR(cast_corridor_ray({-0.75, 0.0, 0.4}, {0, 1, 0}), 2.0, kExact);  // first box's face at y = 2 m
  EXPECT_NEAR(cast_corridor_ray({0.0, 8.5, 2.0}, {-1, 0, 0}), 0.7, kExact);   // the hanging box
  // From inside a box, the box itself is not hit (the wall behind it is).
  EXPECT_NEAR(cast_corridor_ray({-0.75, 2.3, 0.4}, {-1, 0, 0}), 0.25, kExact);
  EXPECT_EQ(cast_corridor_ray({0.0, 0.0, 3.0}, {0, 0, 1}), std::numeric_limits<double>::infinity());
}

TEST(SyntheticCorridor, FilterCloudIsDeterministicAndInsideTheCorridor) {
  const Eigen::Matrix3Xf corridor = make_corridor_cloud(1);
  EXPECT_GT(corridor.cols(), 350000);
  EXPECT_LE(corridor.cols(), 848 * 480);
  EXPECT_TRUE(corridor == make_corridor_cloud(1));
  EXPECT_FALSE(corridor == make_corridor_cloud(2));
  EXPECT_LE(corridor.row(0).cwiseAbs().maxCoeff(), 1.0f + kNoiseMarginM);
  EXPECT_GE(corridor.row(1).minCoeff(), 0.0f);
  EXPECT_LE(corridor.row(1).maxCoeff(), 11.0f);  // depth < 10 m along a pitched axis
  EXPECT_GE(corridor.row(2).minCoeff(), -kNoiseMarginM);
  EXPECT_LE(corridor.row(2).maxCoeff(), 2.5f + kNoiseMarginM);
  EXPECT_EQ(make_corridor_cloud(1, 96, 54).cols(),
            make_corridor_cloud(7, 96, 54).cols());  // the range test uses the true depth
  EXPECT_THROW(make_corridor_cloud(1, 0, 480), std::invalid_argument);
  EXPECT_THROW(make_corridor_cloud(1, 848, 9000), std::invalid_argument);
}

TEST(SyntheticCorridor, MapFramesAreDeterministicAndMove) {
  const SyntheticFrame a = synthetic_corridor_frame(3, 2, 0.05), b = synthetic_corridor_frame(3, 2, 0.05);
  EXPECT_TRUE(a.points_W == b.points_W);
  EXPECT_TRUE(a.T_world_camera.isApprox(b.T_world_camera));
  EXPECT_GT(a.points_W.cols(), 1000);
  EXPECT_LT(a.points_W.cols(), 424 * 240);
  EXPECT_DOUBLE_EQ(a.time_s, 1.0 + 2.0 / 30.0);
  const SyntheticFrame c = synthetic_corridor_frame(3, 30, 0.05);
  EXPECT_NEAR(c.T_world_camera.translation().y() - a.T_world_camera.translation().y(), 0.03 * 28, kExact);
  EXPECT_GT(a.T_world_camera.linear().col(2).y(), 0.9);  // looking down the corridor
  const Eigen::Vector3f origin = a.T_world_camera.translation().cast<float>();
  for (Eigen::Index i = 0; i < a.points_W.cols(); ++i) {
    ASSERT_LT((a.points_W.col(i) - origin).norm(), 5.0f * 1.6f);  // 5 m of depth at the frustum's corner
  }
  EXPECT_THROW(synthetic_corridor_frame(3, 0, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace stvl::bench

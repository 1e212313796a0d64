// STVL's 3D lidar clearing model (model_type 1: ThreeDimensionalLidarFrustum, ros2 403d9ed and noetic-devel
// 5e06daf) on hand-computed points: the horizontal range, the padded vertical cone, the bearing's two formulas and
// the full circle above 6.27 rad; then in the map, where it accelerates decay like the camera's frustum.
#include "mapping/lidar_frustum.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "mapping/voxel_map.hpp"
#include "test_helpers.hpp"

namespace stvl::mapping {
namespace {

constexpr double kPi = 3.14159265358979323846;

ObservationSource lidar(double hfov_rad, double padding_m = 0.0) {
  ObservationSource s;
  s.clearing = true;
  s.model = ClearingModel::kLidar3D;
  s.horizontal_fov_rad = hfov_rad;
  s.vertical_fov_rad = kPi / 3;  // tan(30 deg) = 0.57735
  s.min_z_m = 0.5;
  s.max_z_m = 5.0;
  s.vertical_fov_padding_m = padding_m;
  return s;
}

TEST(LidarFrustum, HorizontalRangeAndVerticalCone) {
  const LidarFrustum f(Eigen::Isometry3d::Identity(), lidar(kPi / 2));
  EXPECT_TRUE(f.contains({2, 0, 0}));
  EXPECT_TRUE(f.contains({2, 0, 1.15}));   // 1.15 / 2 = 0.575 < 0.57735
  EXPECT_FALSE(f.contains({2, 0, 1.16}));  // 0.58
  EXPECT_FALSE(f.contains({2, 0, -1.16}));
  EXPECT_TRUE(f.contains({0.5, 0, 0}));  // r^2 = min_z^2: not below it
  EXPECT_FALSE(f.contains({0.49, 0, 0}));
  EXPECT_TRUE(f.contains({5.0, 0, 0}));  // r^2 = max_z^2
  EXPECT_FALSE(f.contains({5.001, 0, 0}));
  // The range is horizontal: 5.64 m away in 3D, 4.9 m across the floor, inside (2.8 / 4.9 = 0.571).
  EXPECT_TRUE(f.contains({4.9, 0, 2.8}));
}

TEST(LidarFrustum, PaddingShrinksTheConeByMetres) {
  const LidarFrustum padded(Eigen::Isometry3d::Identity(), lidar(kPi / 2, 0.1));
  EXPECT_TRUE(padded.contains({2, 0, 1.0}));    // (1.0 + 0.1) / 2 = 0.55
  EXPECT_FALSE(padded.contains({2, 0, 1.1}));   // (1.1 + 0.1) / 2 = 0.60
  EXPECT_FALSE(padded.contains({2, 0, -1.1}));  // |z| + padding
  EXPECT_TRUE(LidarFrustum(Eigen::Isometry3d::Identity(), lidar(kPi / 2)).contains({2, 0, 1.1}));
}

TEST(LidarFrustum, BearingInFrontAndBehind) {
  const LidarFrustum quarter(Eigen::Isometry3d::Identity(), lidar(kPi / 2));  // +-45 deg
  EXPECT_TRUE(quarter.contains({2, 1.9, 0}));                                 // atan(0.95) = 43.5 deg
  EXPECT_FALSE(quarter.contains({2, 2.1, 0}));                                // 46.4 deg
  EXPECT_FALSE(quarter.contains({0, 2, 0}));                                 // x = 0 takes the rear formula: 0 + 90 deg
  const LidarFrustum wide(Eigen::Isometry3d::Identity(), lidar(1.5 * kPi));  // +-135 deg
  EXPECT_TRUE(wide.contains({0, 2, 0}));                                     // 90 deg
  EXPECT_TRUE(wide.contains({-1, 1.1, 0}));                                  // atan(1 / 1.1) + 90 = 132.3 deg
  EXPECT_FALSE(wide.contains({-1.1, 1, 0}));                                 // atan(1.1) + 90 = 137.7 deg
  EXPECT_FALSE(wide.contains({-2, 0, 0}));                                   // atan(-inf) -> 90 + 90 = 180 deg
  // More than 6.27 rad is the full circle; 6.27 itself is not (half of it 179.6 deg).
  EXPECT_FALSE(LidarFrustum(Eigen::Isometry3d::Identity(), lidar(6.27)).contains({-2, 0.001, 0}));
  EXPECT_TRUE(LidarFrustum(Eigen::Isometry3d::Identity(), lidar(6.2701)).contains({-2, 0.001, 0}));
  EXPECT_TRUE(LidarFrustum(Eigen::Isometry3d::Identity(), lidar(6.2832)).contains({-2, 0, 0}));
}

TEST(LidarFrustum, PoseAndBounds) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();  // facing +y
  T.translation() = Eigen::Vector3d(1, 2, 0.5);
  const LidarFrustum f(T, lidar(kPi / 2));
  EXPECT_TRUE(f.contains({1, 4, 0.5}));
  EXPECT_FALSE(f.contains({3, 2, 0.5}));  // 90 deg to the right
  EXPECT_TRUE(f.may_intersect(Eigen::AlignedBox3d(Eigen::Vector3d(0.9, 3.9, 0.4), Eigen::Vector3d(1.1, 4.1, 0.6))));
  EXPECT_FALSE(f.may_intersect(Eigen::AlignedBox3d(Eigen::Vector3d(7, 2, 0), Eigen::Vector3d(8, 3, 1))));
  EXPECT_NEAR(f.bounds_W().max().x(), 6.0, 1e-5);
  EXPECT_NEAR(f.bounds_W().max().z(), 0.5 + 5.0 * std::tan(kPi / 6), 1e-5);
}

TEST(LidarFrustum, BadSourceOrPoseIsAnError) {
  EXPECT_THROW(LidarFrustum(Eigen::Isometry3d::Identity(), lidar(6.4)), std::invalid_argument);
  EXPECT_THROW(LidarFrustum(Eigen::Isometry3d::Identity(), lidar(kPi / 2, -0.1)), std::invalid_argument);
  ObservationSource camera = lidar(kPi / 2);
  camera.model = ClearingModel::kDepthCamera;
  camera.horizontal_fov_rad = 4.0;
  EXPECT_THROW(camera.validate(), std::invalid_argument);  // only the lidar model takes more than pi
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad(0, 0) = NAN;
  EXPECT_THROW(LidarFrustum(bad, lidar(kPi / 2)), std::invalid_argument);
}

// The camera's link frame (x forward, z up) is the optical frame turned: link x = optical z.
TEST(LidarFrustum, SensorFrameLinkTurnsTheOpticalFrame) {
  const Eigen::Isometry3d T = T_optical_sensor(SensorFrame::kLink);
  EXPECT_TRUE((T * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitZ()));
  EXPECT_TRUE((T * Eigen::Vector3d::UnitY()).isApprox(-Eigen::Vector3d::UnitX()));
  EXPECT_TRUE((T * Eigen::Vector3d::UnitZ()).isApprox(-Eigen::Vector3d::UnitY()));
  EXPECT_TRUE(T_optical_sensor(SensorFrame::kOptical).matrix().isIdentity());
  EXPECT_EQ(parse_sensor_frame("link"), SensorFrame::kLink);
  EXPECT_THROW(parse_sensor_frame("base_link"), std::invalid_argument);
}

// In the map: a voxel inside the lidar's cylinder ages by 1/6 * 6 * 1^3 = 1 s more, one behind the camera's
// optical axis but inside the cylinder too (the model clears all round), one beyond max_z stays as it was.
TEST(LidarFrustum, AcceleratesDecayInTheMap) {
  StvlConfig config = test::exact_config();
  config.voxel_decay_s = 100.0;
  VoxelMap map(config);
  const Eigen::Isometry3d camera = test::camera_looking_along_x({0, 0, 0.5});  // optical z along world +x
  ObservationSource marking = test::wide_source();
  map.mark(test::cloud({{2.0f, 0.0f, 0.5f}, {-2.0f, 0.0f, 0.5f}, {7.0f, 0.0f, 0.5f}}), camera, marking, 0.0);
  ASSERT_EQ(map.size(), 3u);
  ObservationSource source = lidar(6.2832);
  source.max_z_m = 5.0;
  source.decay_acceleration_per_s3 = 6.0;
  source.sensor_frame = SensorFrame::kLink;  // the cylinder's axis up
  Eigen::Matrix3Xf none(3, 0);
  map.clear({{camera, source, &none, &none}}, 1.0);
  const auto time_at = [&](double x) { return *map.lookup({x, 0.0, 0.5}); };
  EXPECT_DOUBLE_EQ(time_at(2.0), -1.0);
  EXPECT_DOUBLE_EQ(time_at(-2.0), -1.0);
  EXPECT_DOUBLE_EQ(time_at(7.0), 0.0);
  // In the optical frame the model's "horizontal" plane is the image plane: a voxel straight ahead lies on the
  // cylinder's axis (r = 0) and outside it.
  source.sensor_frame = SensorFrame::kOptical;
  map.clear({{camera, source, &none, &none}}, 2.0);
  EXPECT_DOUBLE_EQ(time_at(2.0), -1.0);
  EXPECT_DOUBLE_EQ(time_at(7.0), 0.0);
}

}  // namespace
}  // namespace stvl::mapping

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "sim/simulator.hpp"
#include "tests/support/fixture.hpp"

namespace stvl::sim {
namespace {

constexpr double kMaxCrossTrack_m = 0.1;
constexpr double kGoalTolerance_m = 0.06;

struct DriveResult {
  bool finished = false;
  double max_cross_track_m = 0;
  double max_tilt_rad = 0;
  Eigen::Vector2d end_W = Eigen::Vector2d::Zero();
};

DriveResult drive(Simulator& sim, const Path& path, double timeout_s) {
  sim.set_path(path);
  DriveResult r;
  while (!sim.path_finished() && sim.time_s() < timeout_s) {
    sim.step();
    const Eigen::Vector2d p = sim.T_world_base().translation().head<2>();
    r.max_cross_track_m = std::max(r.max_cross_track_m, sim.follower().cross_track_error_m(p));
    r.max_tilt_rad = std::max(r.max_tilt_rad, sim.robot().tilt_rad());
  }
  r.finished = sim.path_finished();
  r.end_W = sim.T_world_base().translation().head<2>();
  return r;
}

TEST(DiffDrive, ReadsWheelGeometryFromModel) {
  World world = World::from_string(test::kFlatWorld, test::worlds_dir());
  DiffDriveRobot robot(world);
  EXPECT_NEAR(robot.wheel_radius_m(), 0.08, 1e-9);
  EXPECT_NEAR(robot.track_width_m(), 0.36, 1e-9);
}

TEST(PathFollowing, FollowsLPath) {
  Simulator sim(World::from_string(test::kFlatWorld, test::worlds_dir()));
  const Path path{{{0, 0}, {3, 0}, {3, 2.5}}, 0.6};
  const DriveResult r = drive(sim, path, 40.0);
  ASSERT_TRUE(r.finished);
  EXPECT_LT(r.max_cross_track_m, kMaxCrossTrack_m);
  EXPECT_LT((r.end_W - Eigen::Vector2d(3, 2.5)).norm(), kGoalTolerance_m);
  EXPECT_LT(r.max_tilt_rad, 0.05);
}

TEST(PathFollowing, FollowsSmoothSPath) {
  Simulator sim(World::from_string(test::kFlatWorld, test::worlds_dir()));
  Path path{{}, 0.5};
  for (int i = 0; i <= 60; ++i) {  // two opposite arcs of radius 1.5 m
    const double t = i / 60.0 * M_PI;
    path.waypoints_W.emplace_back(1.5 * std::sin(t), 1.5 - 1.5 * std::cos(t));
  }
  for (int i = 1; i <= 60; ++i) {
    const double t = i / 60.0 * M_PI;
    path.waypoints_W.emplace_back(-1.5 * std::sin(t), 4.5 - 1.5 * std::cos(t));
  }
  const DriveResult r = drive(sim, path, 60.0);
  ASSERT_TRUE(r.finished);
  EXPECT_LT(r.max_cross_track_m, kMaxCrossTrack_m);
  EXPECT_LT((r.end_W - path.waypoints_W.back()).norm(), kGoalTolerance_m);
}

TEST(PathFollowing, LoopingPathPassesTheFirstWaypointAgainEachLap) {
  Simulator sim(World::from_string(test::kFlatWorld, test::worlds_dir()));
  const Eigen::Vector2d first(0, 0), second(2.5, 0), third(2.5, 1.5);
  sim.set_path({{first, second, third}, 0.6, /*loop=*/true});
  EXPECT_EQ(sim.follower().path().waypoints_W.size(), 4u);  // the closing leg back to the first waypoint
  double left_first_at_s = -1, back_at_first_s = -1, second_again_s = -1;
  double max_cross_track_m = 0;
  while (sim.time_s() < 60.0 && second_again_s < 0) {
    sim.step();
    ASSERT_FALSE(sim.path_finished());
    const Eigen::Vector2d p = sim.T_world_base().translation().head<2>();
    max_cross_track_m = std::max(max_cross_track_m, sim.follower().cross_track_error_m(p));
    if (left_first_at_s < 0 && (p - first).norm() > 1.0) left_first_at_s = sim.time_s();
    if (left_first_at_s > 0 && back_at_first_s < 0 && (p - first).norm() < kGoalTolerance_m)
      back_at_first_s = sim.time_s();
    if (back_at_first_s > 0 && (p - second).norm() < kGoalTolerance_m) second_again_s = sim.time_s();
  }
  ASSERT_GT(back_at_first_s, 0) << "never came back to the first waypoint";
  ASSERT_GT(second_again_s, 0) << "did not go on to the second waypoint after the lap";
  EXPECT_EQ(sim.follower().laps_completed(), 1);
  EXPECT_LT(max_cross_track_m, kMaxCrossTrack_m);
}

// robot.reverse: facing +x, the robot backs 2 m along -x (nav2 #5476's reversing robot): it ends at the path's end
// still facing +x, never turned round, with negative speed commands only.
TEST(PathFollowing, ReversesAlongThePathRearFirst) {
  Simulator sim(World::from_string(test::kFlatWorld, test::worlds_dir()));
  sim.set_start_pose({3.0, 0.0, 0.0});
  Path path{{{3.0, 0.0}, {1.0, 0.0}}, 0.4};
  path.reverse = true;
  const DriveResult r = drive(sim, path, 30.0);
  ASSERT_TRUE(r.finished);
  EXPECT_NEAR(r.end_W.x(), 1.0, 0.05);
  EXPECT_LT(r.max_cross_track_m, 0.05);
  const Eigen::Matrix3d R = sim.T_world_base().rotation();
  EXPECT_LT(std::abs(std::atan2(R(1, 0), R(0, 0))), 0.1);  // still facing +x
  PathFollower follower;
  follower.set_path(path);
  EXPECT_LT(follower.update({3.0, 0.0}, 0.0).v_mps, 0.0);
}

TEST(PathFollowing, ClosedLoopIsNotClosedTwice) {
  PathFollower follower;
  follower.set_path({{{0, 0}, {1, 0}, {1, 1}, {0, 0}}, 0.5, true});
  EXPECT_EQ(follower.path().waypoints_W.size(), 4u);
  follower.set_path({{{0, 0}, {1, 0}}, 0.5, false});
  EXPECT_EQ(follower.path().waypoints_W.size(), 2u);
}

TEST(PathFollowing, RejectsBadPaths) {
  PathFollower follower;
  EXPECT_THROW(follower.set_path({{{0, 0}}, 0.5}), std::invalid_argument);
  EXPECT_THROW(follower.set_path({{{0, 0}, {0, 0}}, 0.5}), std::invalid_argument);
  EXPECT_THROW(follower.set_path({{{0, 0}, {1, 0}}, 0.0}), std::invalid_argument);
  EXPECT_THROW(follower.set_path({{{0, 0}, {1, 0}}, 5.0}), std::invalid_argument);
  EXPECT_THROW(follower.set_path({{{0, 0}, {NAN, 0}}, 0.5}), std::invalid_argument);
  EXPECT_THROW(follower.set_path({{{0, 0}}, 0.5, true}), std::invalid_argument);
  EXPECT_THROW(follower.set_path({{{0, 0}, {1, 0}, {1, 0}}, 0.5, true}), std::invalid_argument);
  EXPECT_NO_THROW(follower.set_path({{{1, 0}, {0, 0}, {1, 0}}, 0.5, true}));  // out and back: 2 distinct points
}

double odometry_error_m(const Simulator& sim, const Eigen::Isometry3d& T_world_start) {
  const Eigen::Isometry3d T_start_base = T_world_start.inverse() * sim.T_world_base();
  return (T_start_base.translation().head<2>() - sim.T_odom_base().translation().head<2>()).norm();
}

TEST(Odometry, MatchesGroundTruthWithoutDrift) {
  Simulator sim(World::from_string(test::kFlatWorld, test::worlds_dir()));
  sim.set_start_pose({1.0, -0.5, 0.3});
  const Eigen::Isometry3d T_world_start = sim.T_world_base();
  const Path path{{{1.0, -0.5}, {3.0, 0.1}, {3.5, 2.0}}, 0.6};
  ASSERT_TRUE(drive(sim, path, 40.0).finished);
  EXPECT_LT(odometry_error_m(sim, T_world_start), 0.03);
  const Eigen::Isometry3d T_map_odom = sim.T_map_odom();
  EXPECT_LT((T_map_odom.translation() - T_world_start.translation()).head<2>().norm(), 0.03);
}

TEST(Odometry, ExactKinematicsWhenDriftOff) {
  WheelOdometry odom(0.1, 0.5);
  for (int i = 0; i < 1000; ++i) odom.update(10.0, 10.0, 0.001);
  EXPECT_DOUBLE_EQ(odom.y_m(), 0.0);
  EXPECT_NEAR(odom.x_m(), 1.0, 1e-12);
  WheelOdometry turn(0.1, 0.5);
  for (int i = 0; i < 1000; ++i) turn.update(-1.0, 1.0, 0.001);  // omega = 0.4 rad/s for 1 s
  EXPECT_NEAR(turn.yaw_rad(), 0.4, 1e-12);
  EXPECT_NEAR(turn.x_m(), 0.0, 1e-12);
}

TEST(Odometry, DriftDivergesAndIsReproducible) {
  auto run = [](bool drift, std::uint64_t seed) {
    SimulatorConfig config;
    config.odometry.drift = drift;
    config.odometry.seed = seed;
    Simulator sim(World::from_string(test::kFlatWorld, test::worlds_dir()), config);
    const Eigen::Isometry3d T_world_start = sim.T_world_base();
    drive(sim, {{{0, 0}, {4, 0}, {4, 2}}, 0.6}, 40.0);
    return std::make_pair(odometry_error_m(sim, T_world_start), sim.T_odom_base());
  };
  const auto exact = run(false, 1);
  const auto drift_a = run(true, 7);
  const auto drift_b = run(true, 7);
  const auto drift_c = run(true, 8);
  EXPECT_GT(drift_a.first, 3 * exact.first);
  EXPECT_GT(drift_a.first, 0.05);
  EXPECT_TRUE(drift_a.second.isApprox(drift_b.second, 0.0));
  EXPECT_FALSE(drift_a.second.isApprox(drift_c.second, 1e-9));
}

TEST(CameraMount, MovesOpticalSite) {
  Simulator sim(World::from_string(test::kFlatWorld, test::worlds_dir()));
  sim.set_start_pose({2.0, 1.0, M_PI / 2});
  sim.robot().set_camera_mount({0.9, 0.2, 0.15});
  const Eigen::Isometry3d T = sim.T_world_camera();
  const Eigen::Isometry3d T_base = sim.T_world_base();
  const Eigen::Isometry3d expected =
      T_base * sim.robot().T_base_camera_link() * DiffDriveRobot::T_camera_link_optical();
  EXPECT_TRUE(T.isApprox(expected, 1e-9));
  EXPECT_NEAR(T.translation().z(), 0.9 + T_base.translation().z(), 1e-9);
  // Optical z looks forward (+y in the world here) and down by the pitch; optical y points down-ish.
  EXPECT_NEAR(T.linear().col(2).y(), std::cos(0.2), 1e-6);
  EXPECT_NEAR(T.linear().col(2).z(), -std::sin(0.2), 1e-6);
  EXPECT_LT(T.linear().col(1).z(), -0.9);
  // The MuJoCo camera looks along -z of its frame: the same direction.
  const int cam = sim.world().camera_id("camera_depth");
  const mjtNum* xmat = sim.world().data()->cam_xmat + 9 * cam;
  const Eigen::Vector3d cam_forward(-xmat[2], -xmat[5], -xmat[8]);
  EXPECT_TRUE(cam_forward.isApprox(T.linear().col(2), 1e-9));
  EXPECT_THROW(sim.robot().set_camera_mount({1.5, 0.0, 0.1}), std::invalid_argument);
  EXPECT_THROW(sim.robot().set_camera_mount({0.5, 2.0, 0.1}), std::invalid_argument);
}

}  // namespace
}  // namespace stvl::sim

// sim/kinematic_drive.hpp: the base placed along the path.
#include <gtest/gtest.h>

#include <cmath>

#include "sim/kinematic_drive.hpp"
#include "tests/sim/polyline.hpp"

namespace stvl::sim {
namespace {

constexpr double kOnPath_m = 0.001;
constexpr double kStep_s = 0.002;

using test::off_polyline;

TEST(KinematicDrive, StaysOnThePathAndEndsAtItsEnd) {
  KinematicDrive drive;
  const Path path{{{0, 0}, {3, 0}, {3.2, 0.1}, {3, 2}, {-1, 2}}, 0.8};  // a gentle corner and sharp ones
  drive.set_path(path, {0, 0, 0.3}, 1.0);
  double worst = 0, top_speed = 0, top_rate = 0;
  Pose2D previous = drive.at(1.0).pose;
  EXPECT_NEAR(previous.yaw_rad, 0.3, 1e-12);  // held at the start before t0
  double t = 1.0;
  for (; !drive.finished(t) && t < 60; t += kStep_s) {
    const KinematicDrive::State s = drive.at(t);
    worst = std::max(worst, off_polyline(path.waypoints_W, {s.pose.x_m, s.pose.y_m}));
    top_speed = std::max(top_speed, s.twist.v_mps);
    top_rate = std::max(top_rate, std::abs(s.twist.omega_radps));
    // Continuous: no jump between steps beyond what the speeds allow.
    EXPECT_LE(std::hypot(s.pose.x_m - previous.x_m, s.pose.y_m - previous.y_m), 0.8 * kStep_s + 1e-9) << t;
    previous = s.pose;
  }
  EXPECT_TRUE(drive.finished(t));
  EXPECT_LT(worst, kOnPath_m);
  EXPECT_NEAR(top_speed, 0.8, 1e-9);
  EXPECT_LE(top_rate, PathFollowerConfig{}.max_angular_speed_radps + 1e-12);
  const Pose2D end = drive.at(t + 5).pose;
  EXPECT_NEAR(end.x_m, -1, 1e-9);
  EXPECT_NEAR(end.y_m, 2, 1e-9);
  EXPECT_NEAR(end.yaw_rad, M_PI, 1e-9);
  EXPECT_EQ(drive.laps_completed(t), 0);
}

TEST(KinematicDrive, LoopsCountLapsAndNeverFinish) {
  KinematicDrive drive;
  Path path{{{0, 0}, {2, 0}, {2, 1}}, 0.5};
  path.loop = true;
  drive.set_path(path, {0, 0, 0}, 0.0);
  std::vector<Eigen::Vector2d> closed = path.waypoints_W;
  closed.push_back(closed.front());
  int laps = 0;
  double worst = 0, previous_yaw = 0;
  for (double t = 0; t < 90; t += kStep_s) {
    const KinematicDrive::State s = drive.at(t);
    worst = std::max(worst, off_polyline(closed, {s.pose.x_m, s.pose.y_m}));
    // The heading never jumps, also where one lap ends and the next begins.
    EXPECT_LT(std::abs(std::remainder(s.pose.yaw_rad - previous_yaw, 2 * M_PI)), 1.3 * kStep_s) << t;
    previous_yaw = s.pose.yaw_rad;
    EXPECT_GE(drive.laps_completed(t), laps);
    laps = drive.laps_completed(t);
    EXPECT_FALSE(drive.finished(t));
  }
  EXPECT_LT(worst, kOnPath_m);
  // A lap: legs of 2, 1 and 2.24 m at 0.5 m/s with 1 s of ramps each (13.5 s) and turns of 1.57, 2.03 and 2.68 rad
  // at 1.2 rad/s with 0.8 s of ramps each (7.6 s): 21.1 s, the first ending at 18.1 s (before the last turn), then
  // 39.2, 60.3 and 81.4 s.
  EXPECT_EQ(laps, 4);
}

TEST(KinematicDrive, RejectsWhatThePathFollowerRejects) {
  KinematicDrive drive;
  EXPECT_THROW(drive.set_path({{{0, 0}}, 0.5}, {}, 0), std::invalid_argument);
  EXPECT_THROW(drive.set_path({{{0, 0}, {1, 0}}, 5.0}, {}, 0), std::invalid_argument);
  EXPECT_THROW(drive.set_path({{{0, 0}, {1, 0}}, 0.5}, {NAN, 0, 0}, 0), std::invalid_argument);
}

}  // namespace
}  // namespace stvl::sim

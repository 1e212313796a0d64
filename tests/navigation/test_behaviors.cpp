// nav2's Spin, BackUp and Wait (navigation/behaviors.hpp) on hand-computed numbers.
#include <cmath>

#include <gtest/gtest.h>

#include "navigation/behaviors.hpp"

namespace stvl::navigation {
namespace {

TEST(Behaviors, SpinSpeedFollowsTheDecelerationRampWithinLimits) {
  BehaviorParams p;  // acc 3.2, vel 0.4 .. 1.0, spin 1.57, 10 Hz
  Behavior b(p, [](const Pose2&) { return true; });
  b.start(BehaviorKind::kSpin, 0.0, {0, 0, 0});
  ASSERT_EQ(b.update(0.0, {0, 0, 0}), BehaviorStatus::kRunning);
  EXPECT_DOUBLE_EQ(b.twist().omega_radps, 1.0);  // sqrt(2 * 3.2 * 1.57) = 3.17 clamped to 1.0
  EXPECT_DOUBLE_EQ(b.twist().v_mps, 0.0);
  // 1.5 rad turned: 0.07 left, sqrt(2 * 3.2 * 0.07) = 0.669.
  ASSERT_EQ(b.update(0.1, {0, 0, 1.5}), BehaviorStatus::kRunning);
  EXPECT_NEAR(b.twist().omega_radps, std::sqrt(2 * 3.2 * 0.07), 1e-9);
  // 1.56 turned: 0.01 left, sqrt(0.064) = 0.253, clamped up to 0.4.
  ASSERT_EQ(b.update(0.2, {0, 0, 1.56}), BehaviorStatus::kRunning);
  EXPECT_DOUBLE_EQ(b.twist().omega_radps, 0.4);
  EXPECT_EQ(b.update(0.3, {0, 0, 1.5700001}), BehaviorStatus::kSucceeded);
  EXPECT_DOUBLE_EQ(b.twist().omega_radps, 0.0);  // stopRobot
}

TEST(Behaviors, SpinCountsTheTurnAcrossPi) {
  Behavior b(BehaviorParams{}, [](const Pose2&) { return true; });
  b.start(BehaviorKind::kSpin, 0.0, {0, 0, 3.0});
  b.update(0.0, {0, 0, 3.0});
  // 3.0 -> -1.8 is +1.483 rad across pi (2 pi - 4.8): 0.087 left, sqrt(2 * 3.2 * 0.087) = 0.746 rad/s.
  ASSERT_EQ(b.update(0.1, {0, 0, -1.8}), BehaviorStatus::kRunning);
  EXPECT_NEAR(b.twist().omega_radps, std::sqrt(2 * 3.2 * (1.57 - (2 * M_PI - 4.8))), 1e-9);
}

TEST(Behaviors, SpinFirstCycleChecksNothingAsNav2Does) {
  int checks = 0;
  Behavior b(BehaviorParams{}, [&](const Pose2&) {
    ++checks;
    return false;
  });
  b.start(BehaviorKind::kSpin, 0.0, {0, 0, 0});
  EXPECT_EQ(b.update(0.0, {0, 0, 0}), BehaviorStatus::kRunning);  // relative yaw 0: the loop breaks at once
  EXPECT_EQ(checks, 0);
  // Turned 0.5 rad: the simulated turn (1.0 rad/s * k / 10 Hz) is checked while under 0.5 rad: k = 1..4.
  EXPECT_EQ(b.update(0.1, {0, 0, 0.5}), BehaviorStatus::kFailed);
  EXPECT_EQ(b.failure(), "collision ahead");
  EXPECT_EQ(checks, 1);  // the first checked pose (k = 0, where it stands) collides
}

TEST(Behaviors, BackUpDrivesBackwardsUntilTheDistance) {
  std::vector<Pose2> checked;
  Behavior b(BehaviorParams{}, [&](const Pose2& p) {
    checked.push_back(p);
    return true;
  });
  b.start(BehaviorKind::kBackUp, 0.0, {1.0, 2.0, 0.0});
  ASSERT_EQ(b.update(0.0, {1.0, 2.0, 0.0}), BehaviorStatus::kRunning);
  EXPECT_DOUBLE_EQ(b.twist().v_mps, -0.15);
  // Simulated at -0.15 m/s * k / 10 Hz while under 0.30 m: k = 0 .. 19 (k = 20 reaches 0.30 and stops).
  ASSERT_EQ(checked.size(), 20u);
  EXPECT_NEAR(checked[19].x_m, 1.0 - 0.15 * 1.9, 1e-12);
  EXPECT_EQ(b.update(2.0, {0.69, 2.0, 0.0}), BehaviorStatus::kSucceeded);
}

TEST(Behaviors, BackUpStopsForAnObstacleBehind) {
  Behavior b(BehaviorParams{}, [](const Pose2& p) { return p.x_m > 0.8; });
  b.start(BehaviorKind::kBackUp, 0.0, {1.0, 0.0, 0.0});
  EXPECT_EQ(b.update(0.0, {1.0, 0.0, 0.0}), BehaviorStatus::kFailed);
  EXPECT_EQ(b.twist().v_mps, 0.0);
}

TEST(Behaviors, WaitSucceedsAfterItsDurationAndTimeAllowanceFailsASpin) {
  Behavior w(BehaviorParams{}, [](const Pose2&) { return true; });
  w.start(BehaviorKind::kWait, 10.0, {});
  EXPECT_EQ(w.update(14.9, {}), BehaviorStatus::kRunning);
  EXPECT_EQ(w.update(15.0, {}), BehaviorStatus::kSucceeded);
  Behavior s(BehaviorParams{}, [](const Pose2&) { return true; });
  s.start(BehaviorKind::kSpin, 0.0, {});
  EXPECT_EQ(s.update(5.0, {}), BehaviorStatus::kRunning);  // stuck: never turns
  EXPECT_EQ(s.update(10.1, {}), BehaviorStatus::kFailed);
  EXPECT_EQ(s.failure(), "time allowance exceeded");
}

TEST(Behaviors, CommandsHoldBetweenCycles) {
  int checks = 0;
  Behavior b(BehaviorParams{}, [&](const Pose2&) {
    ++checks;
    return true;
  });
  b.start(BehaviorKind::kBackUp, 0.0, {});
  b.update(0.0, {});
  const int after_first = checks;
  b.update(0.05, {});  // 20 Hz tick between 10 Hz cycles: nothing recomputed
  EXPECT_EQ(checks, after_first);
  b.update(0.1, {});
  EXPECT_GT(checks, after_first);
}

}  // namespace
}  // namespace stvl::navigation

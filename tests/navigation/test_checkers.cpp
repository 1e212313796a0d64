// controller_server's SimpleGoalChecker and SimpleProgressChecker (navigation/checkers.hpp) against jazzy
// f4108e5b1's nav2_controller/plugins/simple_goal_checker.cpp and simple_progress_checker.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "navigation/checkers.hpp"

namespace stvl::navigation {
namespace {

TEST(GoalChecker, DefaultsAreJazzys) {
  const GoalCheckerParams g;
  EXPECT_EQ(g.xy_goal_tolerance, 0.25);
  EXPECT_EQ(g.yaw_goal_tolerance, 0.25);
  EXPECT_TRUE(g.stateful);
  EXPECT_FALSE(g.symmetric_yaw_tolerance);
  const ProgressCheckerParams p;
  EXPECT_EQ(p.required_movement_radius, 0.5);
  EXPECT_EQ(p.movement_time_allowance, 10.0);
}

TEST(GoalChecker, ReachedInsideBothTolerances) {
  SimpleGoalChecker checker(GoalCheckerParams{0.25, 0.25, false, false});
  const Pose2 goal{1.0, 2.0, 0.5};
  EXPECT_TRUE(checker.is_goal_reached({1.2, 2.1, 0.6}, goal, {}));    // 0.224 m, 0.1 rad
  EXPECT_FALSE(checker.is_goal_reached({1.2, 2.2, 0.5}, goal, {}));   // 0.283 m
  EXPECT_FALSE(checker.is_goal_reached({1.0, 2.0, 0.76}, goal, {}));  // 0.26 rad
  EXPECT_TRUE(checker.is_goal_reached({1.0, 2.25, 0.25}, goal, {}));  // both on the boundary: inclusive
  // Headings wrap: 3.1 and -3.1 are 0.083 rad apart.
  EXPECT_TRUE(checker.is_goal_reached({1.0, 2.0, 3.1}, {1.0, 2.0, -3.1}, {}));
  EXPECT_EQ(checker.xy_goal_tolerance_m(), 0.25);
}

TEST(GoalChecker, StatefulChecksOnlyTheHeadingOnceInside) {
  SimpleGoalChecker checker(GoalCheckerParams{});
  const Pose2 goal{0.0, 0.0, 0.0};
  EXPECT_FALSE(checker.is_goal_reached({0.1, 0.0, 1.0}, goal, {}));  // inside xy, heading off: latched
  EXPECT_TRUE(checker.is_goal_reached({0.4, 0.0, 0.1}, goal, {}));   // 0.4 m out, only the heading counts
  checker.reset();
  EXPECT_FALSE(checker.is_goal_reached({0.4, 0.0, 0.1}, goal, {}));

  SimpleGoalChecker stateless(GoalCheckerParams{0.25, 0.25, false, false});
  EXPECT_FALSE(stateless.is_goal_reached({0.1, 0.0, 1.0}, goal, {}));
  EXPECT_FALSE(stateless.is_goal_reached({0.4, 0.0, 0.1}, goal, {}));
}

TEST(GoalChecker, SymmetricYawAcceptsTheOppositeHeading) {
  SimpleGoalChecker plain(GoalCheckerParams{});
  SimpleGoalChecker symmetric(GoalCheckerParams{0.25, 0.25, true, true});
  EXPECT_FALSE(plain.is_goal_reached({0, 0, M_PI - 0.1}, {0, 0, 0}, {}));
  EXPECT_TRUE(symmetric.is_goal_reached({0, 0, M_PI - 0.1}, {0, 0, 0}, {}));
  EXPECT_FALSE(symmetric.is_goal_reached({0, 0, M_PI / 2}, {0, 0, 0}, {}));
}

TEST(GoalChecker, ValidateNamesTheKey) {
  EXPECT_THROW(SimpleGoalChecker(GoalCheckerParams{-0.1, 0.25, true, false}), std::invalid_argument);
  try {
    GoalCheckerParams{0.25, std::nan(""), true, false}.validate();
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("yaw_goal_tolerance"), std::string::npos);
  }
  EXPECT_THROW(SimpleProgressChecker(ProgressCheckerParams{0.5, -1.0}), std::invalid_argument);
}

TEST(ProgressChecker, FailsAfterTheAllowanceWithoutMoving) {
  SimpleProgressChecker checker(ProgressCheckerParams{});
  EXPECT_TRUE(checker.check({0, 0, 0}, 100.0));    // baseline
  EXPECT_TRUE(checker.check({0.3, 0, 0}, 105.0));  // within 0.5 m
  EXPECT_TRUE(checker.check({0.5, 0, 0}, 110.0));  // exactly 10 s and exactly 0.5 m: neither counts
  EXPECT_FALSE(checker.check({0.4, 0.1, 0}, 110.05));
  // Moving more than the radius sets a new baseline.
  EXPECT_TRUE(checker.check({0.6, 0, 0}, 110.1));
  EXPECT_TRUE(checker.check({0.6, 0, 3.0}, 120.1));  // turning in place is no progress, but 10 s not exceeded
  EXPECT_FALSE(checker.check({0.6, 0, 3.0}, 120.15));
  // reset: the next check starts a new baseline.
  checker.reset();
  EXPECT_TRUE(checker.check({0.6, 0, 0}, 200.0));
  EXPECT_TRUE(checker.check({0.6, 0, 0}, 210.0));
}

TEST(ProgressChecker, TimesCompareInNanosecondsLikeRclcpp) {
  // 200 steps of 0.05 s add up to 10.000000000000002 in doubles; as rclcpp time it is exactly 10 s.
  SimpleProgressChecker checker(ProgressCheckerParams{});
  double t_s = 0.0;
  ASSERT_TRUE(checker.check({0, 0, 0}, t_s));
  for (int i = 1; i <= 200; ++i) {
    t_s += 0.05;
    ASSERT_TRUE(checker.check({0, 0, 0}, t_s)) << i;
  }
  t_s += 0.05;
  EXPECT_FALSE(checker.check({0, 0, 0}, t_s));
}

}  // namespace
}  // namespace stvl::navigation

#pragma once
// controller_server's default goal and progress checkers (ros-navigation/navigation2 jazzy f4108e5b1:
// nav2_controller/plugins/simple_goal_checker.cpp, simple_progress_checker.cpp), rewritten without ROS.
#include <cstdint>

#include "navigation/rpp.hpp"

namespace stvl::navigation {

// goal_checker (nav2_controller::SimpleGoalChecker) keys with jazzy's defaults.
struct GoalCheckerParams {
  double xy_goal_tolerance = 0.25;
  double yaw_goal_tolerance = 0.25;
  bool stateful = true;                  // once inside xy_goal_tolerance, only the heading is checked
  bool symmetric_yaw_tolerance = false;  // accept the goal heading or its opposite

  // Throws std::invalid_argument naming the bad key (negative or non-finite tolerance).
  void validate() const;
};

class SimpleGoalChecker {
 public:
  // Validates params.
  explicit SimpleGoalChecker(GoalCheckerParams params);

  // reset(): check the position again (controller_server calls it on every new plan).
  void reset();

  // isGoalReached: the robot within xy_goal_tolerance of the goal (or latched, when stateful) and its heading
  // within yaw_goal_tolerance; the velocity is not used.
  bool is_goal_reached(const Pose2& robot_W, const Pose2& goal_W, const Twist& velocity);

  // getTolerances' position.x, which RPP reads as its goal distance tolerance.
  double xy_goal_tolerance_m() const { return params_.xy_goal_tolerance; }

 private:
  GoalCheckerParams params_;
  double xy_goal_tolerance_sq_ = 0.0;
  bool check_xy_ = true;
};

// progress_checker (nav2_controller::SimpleProgressChecker) keys with jazzy's defaults.
struct ProgressCheckerParams {
  double required_movement_radius = 0.5;
  double movement_time_allowance = 10.0;

  // Throws std::invalid_argument naming the bad key (negative or non-finite).
  void validate() const;
};

class SimpleProgressChecker {
 public:
  // Validates params.
  explicit SimpleProgressChecker(ProgressCheckerParams params);

  // reset(): forget the baseline (controller_server calls it when a FollowPath goal starts).
  void reset();

  // check(): false once the robot has stayed within required_movement_radius of the baseline pose for more
  // than movement_time_allowance (controller_server then aborts: "Failed to make progress"). Moving farther
  // than the radius, or the first call after reset, sets a new baseline at (robot_W, time_s).
  bool check(const Pose2& robot_W, double time_s);

 private:
  ProgressCheckerParams params_;
  bool baseline_set_ = false;
  Pose2 baseline_W_;
  std::int64_t baseline_time_ns_ = 0;
};

}  // namespace stvl::navigation

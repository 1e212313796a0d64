// controller_server's SimpleGoalChecker and SimpleProgressChecker (ros-navigation/navigation2 jazzy f4108e5b1,
// nav2_controller/plugins/simple_goal_checker.cpp and simple_progress_checker.cpp).
#include "navigation/checkers.hpp"

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace stvl::navigation {
namespace {

// angles::normalize_angle (ROS 2 angles): into (-pi, pi].
double normalize_angle(double a) {
  const double r = std::fmod(a + M_PI, 2.0 * M_PI);
  return r <= 0.0 ? r + M_PI : r - M_PI;
}

// angles::shortest_angular_distance: normalize_angle(to - from).
double shortest_angular_distance(double from_rad, double to_rad) { return normalize_angle(to_rad - from_rad); }

// rclcpp time as integer nanoseconds: sim times to the nearest ns, and Duration::from_seconds' truncation.
std::int64_t time_ns(double time_s) { return std::llround(time_s * 1e9); }
std::int64_t duration_ns(double seconds) { return static_cast<std::int64_t>(seconds * 1e9); }

// tf2::getYaw of the pose's quaternion: the heading in (-pi, pi].
double yaw_of(double yaw_rad) { return std::atan2(std::sin(yaw_rad), std::cos(yaw_rad)); }

void require_non_negative(const char* type, const char* key, double value) {
  if (!(std::isfinite(value) && value >= 0.0)) {
    throw std::invalid_argument(std::string(type) + "." + key + " must be finite and >= 0");
  }
}

}  // namespace

void GoalCheckerParams::validate() const {
  require_non_negative("GoalCheckerParams", "xy_goal_tolerance", xy_goal_tolerance);
  require_non_negative("GoalCheckerParams", "yaw_goal_tolerance", yaw_goal_tolerance);
}

SimpleGoalChecker::SimpleGoalChecker(GoalCheckerParams params) : params_(params) {
  params_.validate();
  xy_goal_tolerance_sq_ = params_.xy_goal_tolerance * params_.xy_goal_tolerance;
}

void SimpleGoalChecker::reset() { check_xy_ = true; }

bool SimpleGoalChecker::is_goal_reached(const Pose2& robot_W, const Pose2& goal_W, const Twist& /*velocity*/) {
  if (check_xy_) {
    const double dx = robot_W.x_m - goal_W.x_m, dy = robot_W.y_m - goal_W.y_m;
    if (dx * dx + dy * dy > xy_goal_tolerance_sq_) return false;
    if (params_.stateful) check_xy_ = false;  // latched: from now on only the heading counts
  }
  const double robot_yaw = yaw_of(robot_W.yaw_rad), goal_yaw = yaw_of(goal_W.yaw_rad);
  if (params_.symmetric_yaw_tolerance) {
    const double forward = shortest_angular_distance(robot_yaw, goal_yaw);
    const double backward = shortest_angular_distance(robot_yaw, normalize_angle(goal_yaw + M_PI));
    return std::fabs(forward) <= params_.yaw_goal_tolerance || std::fabs(backward) <= params_.yaw_goal_tolerance;
  }
  return std::fabs(shortest_angular_distance(robot_yaw, goal_yaw)) <= params_.yaw_goal_tolerance;
}

void ProgressCheckerParams::validate() const {
  require_non_negative("ProgressCheckerParams", "required_movement_radius", required_movement_radius);
  require_non_negative("ProgressCheckerParams", "movement_time_allowance", movement_time_allowance);
}

SimpleProgressChecker::SimpleProgressChecker(ProgressCheckerParams params) : params_(params) { params_.validate(); }

void SimpleProgressChecker::reset() { baseline_set_ = false; }

bool SimpleProgressChecker::check(const Pose2& robot_W, double time_s) {
  // isRobotMovedEnough: strictly farther than the radius from the baseline.
  if (!baseline_set_ ||
      std::hypot(robot_W.x_m - baseline_W_.x_m, robot_W.y_m - baseline_W_.y_m) > params_.required_movement_radius) {
    baseline_W_ = robot_W;
    baseline_time_ns_ = time_ns(time_s);
    baseline_set_ = true;
    return true;
  }
  // Compared in nanoseconds as rclcpp::Time and Duration are.
  return !(time_ns(time_s) - baseline_time_ns_ > duration_ns(params_.movement_time_allowance));
}

}  // namespace stvl::navigation

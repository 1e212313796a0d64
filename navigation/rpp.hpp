#pragma once
// nav2's Regulated Pure Pursuit controller (ros-navigation/navigation2, jazzy f4108e5b1:
// nav2_regulated_pure_pursuit_controller/src/regulated_pure_pursuit_controller.cpp, path_handler.cpp,
// collision_checker.cpp, parameter_handler.cpp, include/.../regulation_functions.hpp), rewritten without ROS.
// The world frame W is the local costmap's frame; the plan is given in that frame too.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mapping/costmap.hpp"

namespace stvl::navigation {

// A planar pose: position and heading (rad, counter-clockwise from +x).
struct Pose2 {
  double x_m = 0.0;
  double y_m = 0.0;
  double yaw_rad = 0.0;
};

// A planar body velocity: forward speed and yaw rate.
struct Twist {
  double v_mps = 0.0;
  double omega_radps = 0.0;
};

// FollowPath (nav2_regulated_pure_pursuit_controller) keys with jazzy's defaults (parameter_handler.cpp).
struct RppParams {
  double desired_linear_vel = 0.5;
  double lookahead_dist = 0.6;
  double min_lookahead_dist = 0.3;
  double max_lookahead_dist = 0.9;
  double lookahead_time = 1.5;
  double rotate_to_heading_angular_vel = 1.8;
  double transform_tolerance = 0.1;  // tf only; kept for the key set, no effect here
  bool use_velocity_scaled_lookahead_dist = false;
  double min_approach_linear_velocity = 0.05;
  double approach_velocity_scaling_dist = 0.6;
  double max_allowed_time_to_collision_up_to_carrot = 1.0;
  bool use_regulated_linear_velocity_scaling = true;
  bool use_cost_regulated_linear_velocity_scaling = true;  // jazzy's default is true
  double cost_scaling_dist = 0.6;
  double cost_scaling_gain = 1.0;
  double inflation_cost_scaling_factor = 3.0;  // <= 0 turns the cost regulation off, as nav2 does
  double regulated_linear_scaling_min_radius = 0.9;
  double regulated_linear_scaling_min_speed = 0.25;
  bool use_fixed_curvature_lookahead = false;
  double curvature_lookahead_dist = 0.6;
  bool use_rotate_to_heading = true;
  double rotate_to_heading_min_angle = 0.785;
  double max_angular_accel = 3.2;
  bool use_cancel_deceleration = false;
  double cancel_deceleration = 3.2;
  bool allow_reversing = false;
  // nullopt: nav2's default, half the costmap's x size in metres ((width - 0.5) * resolution / 2);
  // negative: search the whole plan (nav2 turns it into the largest double).
  std::optional<double> max_robot_pose_search_dist;
  bool interpolate_curvature_after_goal = false;  // needs use_fixed_curvature_lookahead, else nav2 turns it off
  bool use_collision_detection = true;
  bool stateful = true;

  // Throws std::invalid_argument naming the first bad key (non-finite, negative, min > max lookahead, ...).
  void validate() const;
};

// What the controller needs from the local costmap's configuration (nav2_costmap_2d Costmap2DROS keys).
struct LocalCostmapConfig {
  std::vector<Eigen::Vector2d> footprint_m;  // robot-frame polygon; empty: a circle of robot_radius_m
  double robot_radius_m = 0.1;               // costmap `robot_radius`, default 0.1
  double footprint_padding_m = 0.01;         // costmap `footprint_padding`, default 0.01 (a float in nav2)
  bool track_unknown_space = false;          // costmap `track_unknown_space`, default false
};

// nav2's outcome of computeVelocityCommands: kOk, or the exception it would throw (twist then zero).
enum class RppStatus {
  kOk,
  kNoPath,           // InvalidPath "Received plan with zero length"
  kInvalidPath,      // InvalidPath "Received plan with length of one" / "Resulting plan has 0 poses in it."
  kCostmapTooSmall,  // ControllerException: the robot is off the costmap while regulating
  kCollisionAhead,   // NoValidControl "RegulatedPurePursuitController detected collision ahead!"
};

// One control cycle's result.
struct RppCommand {
  Twist twist;
  RppStatus status = RppStatus::kOk;
  std::string message;  // nav2's exception text when status != kOk
  Eigen::Vector2d carrot_W = Eigen::Vector2d::Zero();
  double lookahead_m = 0.0;
  double curvature_per_m = 0.0;  // the regulation curvature used for omega
  bool rotating_to_heading = false;
};

// nav2_costmap_2d::FootprintCollisionChecker::footprintCostAtPose: the footprint placed at pose_W, its edges
// rasterised cell by cell (nav2_util::LineIterator, Bresenham); the largest cost, 254 at the first lethal
// cell, 254 when a vertex is off the map.
double footprint_cost_at_pose(const mapping::Costmap2D& costmap, const Pose2& pose_W,
                              const std::vector<Eigen::Vector2d>& footprint_m);

// RegulatedPurePursuitController::circleSegmentIntersection: where the segment p1-p2 (p1 inside, p2 outside)
// crosses the circle of radius r_m centred on the origin.
Eigen::Vector2d circle_segment_intersection(const Eigen::Vector2d& p1, const Eigen::Vector2d& p2, double r_m);

class RegulatedPurePursuit {
 public:
  // Validates params (std::invalid_argument) and applies nav2's configure-time corrections; the footprint is
  // padded and its inscribed / circumscribed radii taken as Costmap2DROS and LayeredCostmap do.
  RegulatedPurePursuit(RppParams params, LocalCostmapConfig costmap_config);

  // setPlan: the global plan in W (poses with headings); clears the goal-heading latch.
  void set_plan(std::vector<Pose2> path_W);

  // computeVelocityCommands for the robot pose in W and its odometry speed; dt_s = 1 / controller_frequency;
  // goal_xy_tolerance_m = the goal checker's xy tolerance (getTolerances). Prunes the stored plan.
  // robot_plan: the robot's pose in the plan's frame (map) where that is not W: transformGlobalPlan prunes and
  // transforms the plan with it, as nav2 does through tf (map -> odom as localization has it); the costmap's checks
  // use robot_W.
  RppCommand compute(const Pose2& robot_W, const Twist& current_speed, const mapping::Costmap2D& costmap, double dt_s,
                     double goal_xy_tolerance_m, const std::optional<Pose2>& robot_plan = std::nullopt);

  // cancel(): true when the robot may stop now (use_cancel_deceleration off, or the deceleration finished).
  bool cancel();

  // reset(): clears the cancel and goal-heading state (controller_server calls it when a goal ends).
  void reset();

  // The stored plan after pruning (poses behind the robot removed).
  const std::vector<Pose2>& plan_W() const { return plan_W_; }
  // The padded robot-frame footprint the collision check uses.
  const std::vector<Eigen::Vector2d>& footprint_m() const { return footprint_m_; }
  // LayeredCostmap's inscribed and circumscribed radii of the padded footprint.
  double inscribed_radius_m() const { return inscribed_radius_m_; }
  double circumscribed_radius_m() const { return circumscribed_radius_m_; }
  // The parameters after nav2's configure-time corrections.
  const RppParams& params() const { return params_; }

 private:
  // PathHandler::transformGlobalPlan: the stored plan pruned up to the pose nearest the robot, and its poses within
  // the local costmap's half extent in the robot's frame.
  std::vector<Pose2> transform_plan(const Pose2& robot_W, const mapping::Costmap2D& costmap);
  // rotateToHeading: in place at rotate_to_heading_angular_vel, limited by max_angular_accel over dt and by the
  // speed that still stops at the target angle.
  Twist rotate_to_heading(double angle_rad, const Twist& current_speed, double dt_s) const;
  // applyConstraints: the linear speed after the curvature, cost and approach regulation and the cancel ramp.
  double regulated_speed(double pose_cost, double curvature, const std::vector<Pose2>& plan_R, double x_vel_sign,
                         const Twist& current_speed, double dt_s);
  // CollisionChecker::isCollisionImminent: the current pose, then the commanded arc in steps that move the robot
  // about one cell, up to the time limit or the carrot's distance (carrot_m).
  bool collision_imminent(const Pose2& robot_W, const Twist& cmd, double carrot_m,
                          const mapping::Costmap2D& costmap) const;

  RppParams params_;
  bool track_unknown_space_ = false;
  std::vector<Eigen::Vector2d> footprint_m_;
  double inscribed_radius_m_ = 0.0;
  double circumscribed_radius_m_ = 0.0;
  std::vector<Pose2> plan_W_;
  bool cancelling_ = false;
  bool finished_cancelling_ = false;
  bool has_reached_xy_tolerance_ = false;
};

}  // namespace stvl::navigation

#include "navigation/config.hpp"

#include <cmath>
#include <stdexcept>

#include "navigation/footprint.hpp"

namespace stvl::navigation {
namespace {

void require(bool ok, const std::string& key, double value, const std::string& rule) {
  if (!ok) throw std::invalid_argument("navigation." + key + " " + std::to_string(value) + ": " + rule);
}

void validate_costmap(const CostmapParams& c, const std::string& name, double inscribed_m) {
  const auto positive = [&](double v, const std::string& key) {
    require(std::isfinite(v) && v > 0, name + "." + key, v, "must be a positive number");
  };
  if (c.rolling_window) positive(c.width_m, "width"), positive(c.height_m, "height");
  positive(c.resolution_m, "resolution");
  positive(c.update_frequency_hz, "update_frequency");
  positive(c.publish_frequency_hz, "publish_frequency");
  require(std::isfinite(c.inflation.cost_scaling_factor) && c.inflation.cost_scaling_factor >= 0,
          name + ".inflation_layer.cost_scaling_factor", c.inflation.cost_scaling_factor, "must be >= 0");
  require(std::isfinite(c.inflation.inflation_radius_m) && c.inflation.inflation_radius_m >= inscribed_m,
          name + ".inflation_layer.inflation_radius", c.inflation.inflation_radius_m,
          "must be finite and at least the robot's inscribed radius " + std::to_string(inscribed_m) +
              " m (nav2 would inflate nothing beyond the footprint)");
}

}  // namespace

NavigationMode parse_navigation_mode(const std::string& text) {
  if (text == "path") return NavigationMode::kPath;
  if (text == "closed_loop") return NavigationMode::kClosedLoop;
  throw std::invalid_argument("'" + text + "' is not a navigation mode: path or closed_loop");
}

std::vector<Eigen::Vector2d> NavigationConfig::footprint_polygon_m() const {
  return pad_footprint(footprint_m.empty() ? footprint_from_radius(robot_radius_m) : footprint_m, footprint_padding_m);
}

std::vector<std::pair<const char*, double*>> rpp_double_keys(RppParams& p) {
  return {{"desired_linear_vel", &p.desired_linear_vel},
          {"lookahead_dist", &p.lookahead_dist},
          {"min_lookahead_dist", &p.min_lookahead_dist},
          {"max_lookahead_dist", &p.max_lookahead_dist},
          {"lookahead_time", &p.lookahead_time},
          {"rotate_to_heading_angular_vel", &p.rotate_to_heading_angular_vel},
          {"transform_tolerance", &p.transform_tolerance},
          {"min_approach_linear_velocity", &p.min_approach_linear_velocity},
          {"approach_velocity_scaling_dist", &p.approach_velocity_scaling_dist},
          {"max_allowed_time_to_collision_up_to_carrot", &p.max_allowed_time_to_collision_up_to_carrot},
          {"cost_scaling_dist", &p.cost_scaling_dist},
          {"cost_scaling_gain", &p.cost_scaling_gain},
          {"inflation_cost_scaling_factor", &p.inflation_cost_scaling_factor},
          {"regulated_linear_scaling_min_radius", &p.regulated_linear_scaling_min_radius},
          {"regulated_linear_scaling_min_speed", &p.regulated_linear_scaling_min_speed},
          {"curvature_lookahead_dist", &p.curvature_lookahead_dist},
          {"rotate_to_heading_min_angle", &p.rotate_to_heading_min_angle},
          {"max_angular_accel", &p.max_angular_accel},
          {"cancel_deceleration", &p.cancel_deceleration}};
}

std::vector<std::pair<const char*, bool*>> rpp_bool_keys(RppParams& p) {
  return {{"use_velocity_scaled_lookahead_dist", &p.use_velocity_scaled_lookahead_dist},
          {"use_regulated_linear_velocity_scaling", &p.use_regulated_linear_velocity_scaling},
          {"use_cost_regulated_linear_velocity_scaling", &p.use_cost_regulated_linear_velocity_scaling},
          {"use_fixed_curvature_lookahead", &p.use_fixed_curvature_lookahead},
          {"use_rotate_to_heading", &p.use_rotate_to_heading},
          {"use_cancel_deceleration", &p.use_cancel_deceleration},
          {"allow_reversing", &p.allow_reversing},
          {"interpolate_curvature_after_goal", &p.interpolate_curvature_after_goal},
          {"use_collision_detection", &p.use_collision_detection},
          {"stateful", &p.stateful}};
}

double NavigationConfig::inscribed_radius_m() const { return inscribed_circumscribed_m(footprint_polygon_m()).first; }

void NavigationConfig::validate() const {
  for (const auto& [key, v] :
       {std::pair<const char*, double>{"goal[0]", goal.x_m}, {"goal[1]", goal.y_m}, {"goal[2]", goal.yaw_rad}})
    require(std::isfinite(v), key, v, "must be finite");
  if (footprint_m.empty())
    require(std::isfinite(robot_radius_m) && robot_radius_m > 0, "robot_radius", robot_radius_m,
            "must be a positive number");
  else if (footprint_m.size() < 3)
    throw std::invalid_argument("navigation.footprint: a polygon needs at least 3 points");
  require(std::isfinite(footprint_padding_m) && footprint_padding_m >= 0, "footprint_padding", footprint_padding_m,
          "must be finite and >= 0");
  require(std::isfinite(controller_frequency_hz) && controller_frequency_hz > 0, "controller_frequency",
          controller_frequency_hz, "must be a positive number");
  require(std::isfinite(controller_costmap_timeout_s) && controller_costmap_timeout_s >= 0, "costmap_update_timeout",
          controller_costmap_timeout_s, "must be >= 0 s");
  require(std::isfinite(planner_costmap_timeout_s) && planner_costmap_timeout_s >= 0, "costmap_update_timeout",
          planner_costmap_timeout_s, "must be >= 0 s");
  require(std::isfinite(failure_tolerance_s) && (failure_tolerance_s >= 0 || failure_tolerance_s == -1.0),
          "failure_tolerance", failure_tolerance_s, "must be >= 0 (or -1: never abort)");
  require(std::isfinite(replan_frequency_hz) && replan_frequency_hz > 0, "replan_frequency", replan_frequency_hz,
          "must be a positive number");
  require(number_of_retries >= 0, "number_of_retries", number_of_retries, "must be >= 0");
  const double inscribed = inscribed_radius_m();
  validate_costmap(local_costmap, "local_costmap", inscribed);
  validate_costmap(global_costmap, "global_costmap", inscribed);
  planner.validate();
  controller.validate();
  const BehaviorParams& b = behaviors;
  for (const auto& [key, v] : {std::pair<const char*, double>{"behaviors.cycle_frequency", b.cycle_frequency_hz},
                               {"behaviors.simulate_ahead_time", b.simulate_ahead_time_s},
                               {"behaviors.max_rotational_vel", b.max_rotational_vel},
                               {"behaviors.rotational_acc_lim", b.rotational_acc_lim},
                               {"behaviors.time_allowance", b.time_allowance_s},
                               {"behaviors.backup_speed", b.backup_speed_mps}})
    require(std::isfinite(v) && v > 0, key, v, "must be a positive number");
  for (const auto& [key, v] : {std::pair<const char*, double>{"behaviors.min_rotational_vel", b.min_rotational_vel},
                               {"behaviors.spin_dist", std::abs(b.spin_dist_rad)},
                               {"behaviors.backup_dist", std::abs(b.backup_dist_m)},
                               {"behaviors.wait_duration", b.wait_duration_s}})
    require(std::isfinite(v) && v >= 0, key, v, "must be finite and >= 0");
  require(b.min_rotational_vel <= b.max_rotational_vel, "behaviors.min_rotational_vel", b.min_rotational_vel,
          "must not exceed max_rotational_vel");
}

}  // namespace stvl::navigation

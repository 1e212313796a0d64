// nav2's Regulated Pure Pursuit controller; every function names the nav2 code it follows
// (ros-navigation/navigation2 jazzy f4108e5b1, nav2_regulated_pure_pursuit_controller unless said otherwise).
#include "navigation/rpp.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "navigation/footprint.hpp"

namespace stvl::navigation {
namespace {

constexpr double kLethal = 254.0;       // nav2_costmap_2d LETHAL_OBSTACLE
constexpr double kNoInformation = 255;  // nav2_costmap_2d NO_INFORMATION
constexpr double kFreeSpace = 0.0;      // nav2_costmap_2d FREE_SPACE

// angles::normalize_angle (ROS 2 angles): into (-pi, pi].
double normalize_angle(double a) {
  const double r = std::fmod(a + M_PI, 2.0 * M_PI);
  return r <= 0.0 ? r + M_PI : r - M_PI;
}

// nav2_util::geometry_utils::euclidean_distance (2D).
double dist(const Pose2& a, const Pose2& b) { return std::hypot(a.x_m - b.x_m, a.y_m - b.y_m); }

// RegulatedPurePursuitController::calculateCurvature: 2y / L^2, 0 when the carrot is within sqrt(0.001).
double curvature_of(const Eigen::Vector2d& carrot_R) {
  const double d2 = carrot_R.squaredNorm();
  return d2 > 0.001 ? 2.0 * carrot_R.y() / d2 : 0.0;
}

// RegulatedPurePursuitController::getLookAheadPoint over the plan in the robot frame R.
Eigen::Vector2d lookahead_point(double lookahead_m, const std::vector<Pose2>& plan_R, bool interpolate_after_goal) {
  auto pos = [&](std::size_t i) { return Eigen::Vector2d(plan_R[i].x_m, plan_R[i].y_m); };
  std::size_t i = 0;
  while (i < plan_R.size() && std::hypot(plan_R[i].x_m, plan_R[i].y_m) < lookahead_m) ++i;
  if (i == plan_R.size()) {
    const std::size_t last = plan_R.size() - 1;
    // nav2 reads the pose before the last one here; a one-pose plan is undefined there, the last pose here.
    if (!interpolate_after_goal || last == 0) return pos(last);
    const Eigen::Vector2d d = pos(last) - pos(last - 1);
    const double heading = std::atan2(d.y(), d.x());
    const Eigen::Vector2d projected = pos(last) + lookahead_m * Eigen::Vector2d(std::cos(heading), std::sin(heading));
    return circle_segment_intersection(pos(last), projected, lookahead_m);
  }
  if (i == 0) return pos(0);
  return circle_segment_intersection(pos(i - 1), pos(i), lookahead_m);
}

// RegulatedPurePursuitController::findVelocitySignChange: distance to the first cusp (or overlapping poses
// with different headings), the largest double when none.
double distance_to_cusp(const std::vector<Pose2>& plan_R) {
  for (std::size_t i = 1; i + 1 < plan_R.size(); ++i) {
    const Pose2 &a = plan_R[i - 1], &b = plan_R[i], &c = plan_R[i + 1];
    const double oa_x = b.x_m - a.x_m, oa_y = b.y_m - a.y_m, ab_x = c.x_m - b.x_m, ab_y = c.y_m - b.y_m;
    if (oa_x * ab_x + oa_y * ab_y < 0.0) return std::hypot(b.x_m, b.y_m);
    if ((std::hypot(oa_x, oa_y) == 0.0 && a.yaw_rad != b.yaw_rad) ||
        (std::hypot(ab_x, ab_y) == 0.0 && b.yaw_rad != c.yaw_rad)) {
      return std::hypot(b.x_m, b.y_m);
    }
  }
  return std::numeric_limits<double>::max();
}

// heuristics::curvatureConstraint (regulation_functions.hpp): v * r / r_min below r_min.
double curvature_constraint(double v, double curvature, double min_radius) {
  const double radius = std::fabs(1.0 / curvature);
  return radius < min_radius ? v * (1.0 - std::fabs(radius - min_radius) / min_radius) : v;
}

// heuristics::approachVelocityConstraint: scale by the straight distance to the plan's end over
// approach_velocity_scaling_dist once the remaining path length is below it; floored at min_approach.
double approach_constraint(double v, const std::vector<Pose2>& plan_R, double min_approach, double scaling_dist) {
  double remaining = 0.0;
  for (std::size_t i = 0; i + 1 < plan_R.size(); ++i) remaining += dist(plan_R[i], plan_R[i + 1]);
  double scale = 1.0;
  if (remaining < scaling_dist) scale = std::hypot(plan_R.back().x_m, plan_R.back().y_m) / scaling_dist;
  const double approach = std::max(v * scale, min_approach);
  return std::min(v, approach);
}

void require(bool ok, const char* key, const char* what) {
  if (!ok) throw std::invalid_argument(std::string("RppParams.") + key + " " + what);
}

}  // namespace

Eigen::Vector2d circle_segment_intersection(const Eigen::Vector2d& p1, const Eigen::Vector2d& p2, double r_m) {
  // Circle-line intersection (mathworld), taking the root on the segment: the sign follows which end is farther.
  const double dx = p2.x() - p1.x(), dy = p2.y() - p1.y();
  const double dr2 = dx * dx + dy * dy;
  const double cross = p1.x() * p2.y() - p2.x() * p1.y();
  const double dd = p2.squaredNorm() - p1.squaredNorm();
  const double root = std::sqrt(r_m * r_m * dr2 - cross * cross);
  const double s = std::copysign(1.0, dd);
  return {(cross * dy + s * dx * root) / dr2, (-cross * dx + s * dy * root) / dr2};
}

double footprint_cost_at_pose(const mapping::Costmap2D& costmap, const Pose2& pose_W,
                              const std::vector<Eigen::Vector2d>& footprint_m) {
  // FootprintCollisionChecker::footprintCostAtPose: the footprint placed, then footprintCost (footprint.hpp).
  return footprint_cost(costmap, place_footprint(footprint_m, pose_W.x_m, pose_W.y_m, pose_W.yaw_rad));
}

void RppParams::validate() const {
  const std::pair<const char*, double> finite_keys[] = {
      {"desired_linear_vel", desired_linear_vel},
      {"lookahead_dist", lookahead_dist},
      {"min_lookahead_dist", min_lookahead_dist},
      {"max_lookahead_dist", max_lookahead_dist},
      {"lookahead_time", lookahead_time},
      {"rotate_to_heading_angular_vel", rotate_to_heading_angular_vel},
      {"transform_tolerance", transform_tolerance},
      {"min_approach_linear_velocity", min_approach_linear_velocity},
      {"approach_velocity_scaling_dist", approach_velocity_scaling_dist},
      {"max_allowed_time_to_collision_up_to_carrot", max_allowed_time_to_collision_up_to_carrot},
      {"cost_scaling_dist", cost_scaling_dist},
      {"cost_scaling_gain", cost_scaling_gain},
      {"inflation_cost_scaling_factor", inflation_cost_scaling_factor},
      {"regulated_linear_scaling_min_radius", regulated_linear_scaling_min_radius},
      {"regulated_linear_scaling_min_speed", regulated_linear_scaling_min_speed},
      {"curvature_lookahead_dist", curvature_lookahead_dist},
      {"rotate_to_heading_min_angle", rotate_to_heading_min_angle},
      {"max_angular_accel", max_angular_accel},
      {"cancel_deceleration", cancel_deceleration},
  };
  for (const auto& [key, value] : finite_keys) {
    require(std::isfinite(value), key, "must be finite");
    // Every key but the inflation factor (nav2 turns cost regulation off when it is <= 0) is non-negative.
    if (std::string(key) != "inflation_cost_scaling_factor") require(value >= 0.0, key, "must be >= 0");
  }
  require(min_lookahead_dist <= max_lookahead_dist, "min_lookahead_dist", "must be <= max_lookahead_dist");
  require(max_angular_accel > 0.0, "max_angular_accel", "must be > 0");
  require(!use_cost_regulated_linear_velocity_scaling || cost_scaling_dist > 0.0, "cost_scaling_dist",
          "must be > 0 with use_cost_regulated_linear_velocity_scaling");
  require(!max_robot_pose_search_dist || !std::isnan(*max_robot_pose_search_dist), "max_robot_pose_search_dist",
          "must not be NaN");
}

RegulatedPurePursuit::RegulatedPurePursuit(RppParams params, LocalCostmapConfig costmap_config)
    : params_(std::move(params)), track_unknown_space_(costmap_config.track_unknown_space) {
  params_.validate();
  // ParameterHandler's configure-time corrections (parameter_handler.cpp).
  if (params_.max_robot_pose_search_dist && *params_.max_robot_pose_search_dist < 0.0) {
    params_.max_robot_pose_search_dist = std::numeric_limits<double>::max();
  }
  if (!params_.use_fixed_curvature_lookahead) params_.interpolate_curvature_after_goal = false;
  if (params_.inflation_cost_scaling_factor <= 0.0) params_.use_cost_regulated_linear_velocity_scaling = false;

  // Costmap2DROS: makeFootprintFromRadius (16 points) or the polygon, then padFootprint (footprint.hpp).
  if (!std::isfinite(costmap_config.footprint_padding_m))
    throw std::invalid_argument("LocalCostmapConfig.footprint_padding_m must be finite");
  if (costmap_config.footprint_m.empty()) {
    const double r = costmap_config.robot_radius_m;
    if (!(std::isfinite(r) && r > 0.0)) throw std::invalid_argument("LocalCostmapConfig.robot_radius_m must be > 0");
    footprint_m_ = footprint_from_radius(r);
  } else {
    if (costmap_config.footprint_m.size() < 3) {
      throw std::invalid_argument("LocalCostmapConfig.footprint_m needs at least three points");
    }
    for (const Eigen::Vector2d& p : costmap_config.footprint_m) {
      if (!p.allFinite()) throw std::invalid_argument("LocalCostmapConfig.footprint_m must be finite");
    }
    footprint_m_ = costmap_config.footprint_m;
  }
  footprint_m_ = pad_footprint(footprint_m_, costmap_config.footprint_padding_m);
  // LayeredCostmap::setFootprint -> calculateMinAndMaxDistances (footprint.cpp): over vertices and edges.
  std::tie(inscribed_radius_m_, circumscribed_radius_m_) = inscribed_circumscribed_m(footprint_m_);
}

void RegulatedPurePursuit::set_plan(std::vector<Pose2> path_W) {
  has_reached_xy_tolerance_ = false;
  plan_W_ = std::move(path_W);
}

bool RegulatedPurePursuit::cancel() {
  if (!params_.use_cancel_deceleration) return true;
  cancelling_ = true;
  return finished_cancelling_;
}

void RegulatedPurePursuit::reset() {
  cancelling_ = false;
  finished_cancelling_ = false;
  has_reached_xy_tolerance_ = false;
}

std::vector<Pose2> RegulatedPurePursuit::transform_plan(const Pose2& robot_W, const mapping::Costmap2D& costmap) {
  const double search_dist_m =
      params_.max_robot_pose_search_dist.value_or((costmap.width - 1 + 0.5) * costmap.resolution_m / 2.0);
  // first_after_integrated_distance: the first pose whose integrated distance along the plan exceeds the bound.
  std::size_t upper = plan_W_.size();
  double along_m = 0.0;
  for (std::size_t i = 0; i + 1 < plan_W_.size(); ++i) {
    along_m += dist(plan_W_[i], plan_W_[i + 1]);
    if (along_m > search_dist_m) {
      upper = i + 1;
      break;
    }
  }
  // min_by: the closest pose before the bound, the last one on ties.
  std::size_t begin = 0;
  double best_m = dist(robot_W, plan_W_[0]);
  for (std::size_t i = 1; i < upper; ++i) {
    const double d = dist(robot_W, plan_W_[i]);
    if (d <= best_m) {
      best_m = d;
      begin = i;
    }
  }
  // Keep two poses to interpolate the end direction (nav2 steps before the plan's start when upper == 1).
  if (plan_W_.size() > 1 && upper >= 2 && begin == upper - 1) begin = upper - 2;
  // Drop the poses beyond the local costmap's half extent (Costmap2D::getSizeInMeters = (n - 0.5) * res).
  const double extent_m =
      std::max((costmap.width - 1 + 0.5) * costmap.resolution_m, (costmap.height - 1 + 0.5) * costmap.resolution_m) /
      2.0;
  std::size_t end = begin;
  while (end < plan_W_.size() && !(dist(plan_W_[end], robot_W) > extent_m)) ++end;
  const double cr = std::cos(robot_W.yaw_rad), sr = std::sin(robot_W.yaw_rad);
  std::vector<Pose2> plan_R;
  plan_R.reserve(end - begin);
  for (std::size_t i = begin; i < end; ++i) {
    const double dx = plan_W_[i].x_m - robot_W.x_m, dy = plan_W_[i].y_m - robot_W.y_m;
    plan_R.push_back({cr * dx + sr * dy, -sr * dx + cr * dy, normalize_angle(plan_W_[i].yaw_rad - robot_W.yaw_rad)});
  }
  plan_W_.erase(plan_W_.begin(), plan_W_.begin() + static_cast<std::ptrdiff_t>(begin));
  return plan_R;
}

Twist RegulatedPurePursuit::rotate_to_heading(double angle_rad, const Twist& current_speed, double dt_s) const {
  const double sign = angle_rad > 0.0 ? 1.0 : -1.0;
  double w = std::clamp(sign * params_.rotate_to_heading_angular_vel,
                        current_speed.omega_radps - params_.max_angular_accel * dt_s,
                        current_speed.omega_radps + params_.max_angular_accel * dt_s);
  const double max_to_stop = std::sqrt(2 * params_.max_angular_accel * std::fabs(angle_rad));
  if (std::fabs(w) > max_to_stop) w = sign * max_to_stop;
  return Twist{0.0, w};
}

double RegulatedPurePursuit::regulated_speed(double pose_cost, double curvature, const std::vector<Pose2>& plan_R,
                                             double x_vel_sign, const Twist& current_speed, double dt_s) {
  double v = params_.desired_linear_vel;
  const double curvature_v = params_.use_regulated_linear_velocity_scaling
                                 ? curvature_constraint(v, curvature, params_.regulated_linear_scaling_min_radius)
                                 : v;
  double cost_v = v;
  // heuristics::costConstraint: the obstacle distance implied by the inflation decay at the robot's cell.
  if (params_.use_cost_regulated_linear_velocity_scaling && pose_cost != kNoInformation && pose_cost != kFreeSpace) {
    const double k = params_.inflation_cost_scaling_factor;
    // nav2 writes log(253.0f): with libstdc++'s <math.h> in scope that is the float overload.
    const double log_inscribed = static_cast<double>(std::log(253.0f));
    const double obstacle_m = (k * inscribed_radius_m_ - std::log(pose_cost) + log_inscribed) / k;
    if (obstacle_m < params_.cost_scaling_dist) {
      cost_v = v * (params_.cost_scaling_gain * obstacle_m / params_.cost_scaling_dist);
    }
  }
  v = std::max(std::min(cost_v, curvature_v), params_.regulated_linear_scaling_min_speed);
  v = approach_constraint(v, plan_R, params_.min_approach_linear_velocity, params_.approach_velocity_scaling_dist);
  v = x_vel_sign * std::clamp(std::fabs(v), 0.0, params_.desired_linear_vel);
  if (cancelling_) {
    v = current_speed.v_mps - x_vel_sign * dt_s * params_.cancel_deceleration;
    if ((x_vel_sign > 0 && v <= 0) || (x_vel_sign < 0 && v >= 0)) {
      v = 0.0;
      finished_cancelling_ = true;
    }
  }
  return v;
}

bool RegulatedPurePursuit::collision_imminent(const Pose2& robot_W, const Twist& cmd, double carrot_m,
                                              const mapping::Costmap2D& costmap) const {
  auto in_collision = [&](double x, double y, double theta) {
    int cx = 0, cy = 0;
    if (!world_to_cell(costmap, x, y, cx, cy)) return false;  // nav2 warns and proceeds
    const double cost = footprint_cost_at_pose(costmap, {x, y, theta}, footprint_m_);
    if (cost == kNoInformation && track_unknown_space_) return false;
    return cost >= kLethal;
  };
  if (in_collision(robot_W.x_m, robot_W.y_m, robot_W.yaw_rad)) return true;
  const double v = cmd.v_mps, w = cmd.omega_radps;
  double step_s = std::numeric_limits<double>::infinity();  // nav2 divides by zero speed here
  if (std::fabs(v) < 0.01 && std::fabs(w) > 0.01) {
    step_s = 2.0 * std::sin((costmap.resolution_m / 2) / circumscribed_radius_m_) / std::fabs(w);
  } else if (v != 0.0) {
    step_s = costmap.resolution_m / std::fabs(v);
  }
  Pose2 p = robot_W;
  for (int i = 1; i * step_s < params_.max_allowed_time_to_collision_up_to_carrot;) {
    ++i;
    p.x_m += step_s * (v * std::cos(p.yaw_rad));
    p.y_m += step_s * (v * std::sin(p.yaw_rad));
    p.yaw_rad += step_s * w;
    if (std::hypot(p.x_m - robot_W.x_m, p.y_m - robot_W.y_m) > carrot_m) break;
    if (in_collision(p.x_m, p.y_m, p.yaw_rad)) return true;
  }
  return false;
}

RppCommand RegulatedPurePursuit::compute(const Pose2& robot_W, const Twist& current_speed,
                                         const mapping::Costmap2D& costmap, double dt_s, double goal_xy_tolerance_m,
                                         const std::optional<Pose2>& robot_plan) {
  if (!(costmap.width > 0 && costmap.height > 0 && costmap.resolution_m > 0.0 &&
        costmap.cells.size() == static_cast<std::size_t>(costmap.width) * costmap.height)) {
    throw std::invalid_argument("RegulatedPurePursuit::compute: malformed costmap");
  }
  if (!(std::isfinite(dt_s) && dt_s > 0.0)) throw std::invalid_argument("RegulatedPurePursuit::compute: dt_s <= 0");
  RppCommand out;
  auto fail = [&out](RppStatus status, const char* message) {
    out.twist = Twist{};
    out.status = status;
    out.message = message;
    return out;
  };

  // PathHandler::transformGlobalPlan (path_handler.cpp).
  if (plan_W_.empty()) return fail(RppStatus::kNoPath, "Received plan with zero length");
  if (params_.interpolate_curvature_after_goal && plan_W_.size() == 1) {
    return fail(RppStatus::kInvalidPath, "Received plan with length of one");
  }
  const std::vector<Pose2> plan_R = transform_plan(robot_plan.value_or(robot_W), costmap);
  if (plan_R.empty()) return fail(RppStatus::kInvalidPath, "Resulting plan has 0 poses in it.");

  // getLookAheadDistance, and the cusp limit when reversing.
  double lookahead_m = params_.lookahead_dist;
  if (params_.use_velocity_scaled_lookahead_dist) {
    lookahead_m = std::clamp(std::fabs(current_speed.v_mps) * params_.lookahead_time, params_.min_lookahead_dist,
                             params_.max_lookahead_dist);
  }
  double curvature_lookahead_m = params_.curvature_lookahead_dist;
  if (params_.allow_reversing) {
    const double cusp_m = distance_to_cusp(plan_R);
    lookahead_m = std::min(lookahead_m, cusp_m);
    curvature_lookahead_m = std::min(curvature_lookahead_m, cusp_m);
  }
  const Eigen::Vector2d carrot_R = lookahead_point(lookahead_m, plan_R, false);
  Eigen::Vector2d rotate_carrot_R = carrot_R;
  double curvature = curvature_of(carrot_R);
  if (params_.use_fixed_curvature_lookahead) {
    rotate_carrot_R = lookahead_point(curvature_lookahead_m, plan_R, params_.interpolate_curvature_after_goal);
    curvature = curvature_of(rotate_carrot_R);
  }
  const double cr = std::cos(robot_W.yaw_rad), sr = std::sin(robot_W.yaw_rad);
  out.lookahead_m = lookahead_m;
  out.carrot_W = Eigen::Vector2d(robot_W.x_m + cr * carrot_R.x() - sr * carrot_R.y(),
                                 robot_W.y_m + sr * carrot_R.x() + cr * carrot_R.y());
  out.curvature_per_m = curvature;
  const double x_vel_sign = params_.allow_reversing && carrot_R.x() < 0.0 ? -1.0 : 1.0;

  // shouldRotateToGoalHeading (stateful latch on the carrot's distance) and shouldRotateToPath.
  bool to_goal_heading = false;
  if (params_.use_rotate_to_heading) {
    const bool within = std::hypot(carrot_R.x(), carrot_R.y()) < goal_xy_tolerance_m;
    if (params_.stateful) {
      if (!has_reached_xy_tolerance_ && within) has_reached_xy_tolerance_ = true;
      to_goal_heading = has_reached_xy_tolerance_;
    } else {
      to_goal_heading = within;
    }
  }
  double angle_to_path = std::atan2(rotate_carrot_R.y(), rotate_carrot_R.x());
  if (x_vel_sign < 0.0) angle_to_path = normalize_angle(angle_to_path + M_PI);
  Twist cmd;
  if (to_goal_heading) {
    out.rotating_to_heading = true;
    cmd = rotate_to_heading(plan_R.back().yaw_rad, current_speed, dt_s);
  } else if (params_.use_rotate_to_heading && std::fabs(angle_to_path) > params_.rotate_to_heading_min_angle) {
    out.rotating_to_heading = true;
    cmd = rotate_to_heading(angle_to_path, current_speed, dt_s);
  } else {
    // applyConstraints, with CollisionChecker::costAtPose at the robot's cell.
    int mx = 0, my = 0;
    if (!world_to_cell(costmap, robot_W.x_m, robot_W.y_m, mx, my)) {
      return fail(RppStatus::kCostmapTooSmall,
                  "RegulatedPurePursuitController: Dimensions of the costmap are too small to encapsulate the robot "
                  "footprint at current speeds!");
    }
    const double pose_cost = costmap.cells[static_cast<std::size_t>(my) * costmap.width + mx];
    const double v = regulated_speed(pose_cost, curvature, plan_R, x_vel_sign, current_speed, dt_s);
    cmd = Twist{v, v * curvature};
  }
  // CollisionChecker::isCollisionImminent (collision_checker.cpp).
  if (params_.use_collision_detection &&
      collision_imminent(robot_W, cmd, std::hypot(carrot_R.x(), carrot_R.y()), costmap))
    return fail(RppStatus::kCollisionAhead, "RegulatedPurePursuitController detected collision ahead!");
  out.twist = cmd;
  return out;
}

}  // namespace stvl::navigation

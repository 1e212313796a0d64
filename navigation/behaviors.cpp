#include "navigation/behaviors.hpp"

#include <cmath>

namespace stvl::navigation {

const char* to_string(BehaviorKind kind) {
  switch (kind) {
    case BehaviorKind::kSpin: return "spin";
    case BehaviorKind::kBackUp: return "backup";
    case BehaviorKind::kWait: return "wait";
  }
  return "?";
}

Behavior::Behavior(const BehaviorParams& params, CollisionFree collision_free)
    : params_(params), collision_free_(std::move(collision_free)) {}

void Behavior::start(BehaviorKind kind, double time_s, const Pose2& pose) {
  kind_ = kind;
  start_s_ = next_cycle_s_ = time_s;
  initial_ = pose;
  prev_yaw_ = pose.yaw_rad;
  relative_yaw_ = 0;
  twist_ = {};
  status_ = BehaviorStatus::kRunning;
  failure_.clear();
}

BehaviorStatus Behavior::update(double time_s, const Pose2& pose) {
  if (status_ != BehaviorStatus::kRunning) return status_;
  constexpr double kEpsilon_s = 1e-9;
  if (time_s + kEpsilon_s < next_cycle_s_) return status_;  // between cycles: the last command holds
  next_cycle_s_ += 1.0 / params_.cycle_frequency_hz;
  status_ = cycle(time_s, pose);
  if (status_ != BehaviorStatus::kRunning) twist_ = {};  // stopRobot()
  return status_;
}

BehaviorStatus Behavior::cycle(double time_s, const Pose2& pose) {
  if (kind_ == BehaviorKind::kWait)
    return time_s - start_s_ >= params_.wait_duration_s ? BehaviorStatus::kSucceeded : BehaviorStatus::kRunning;
  if (time_s - start_s_ > params_.time_allowance_s) {
    failure_ = "time allowance exceeded";
    return BehaviorStatus::kFailed;
  }
  if (kind_ == BehaviorKind::kSpin) {  // Spin::onCycleUpdate
    double delta_yaw = pose.yaw_rad - prev_yaw_;
    if (std::abs(delta_yaw) > M_PI) delta_yaw = std::copysign(2 * M_PI - std::abs(delta_yaw), prev_yaw_);
    relative_yaw_ += delta_yaw;
    prev_yaw_ = pose.yaw_rad;
    const double remaining = std::abs(params_.spin_dist_rad) - std::abs(relative_yaw_);
    if (remaining < 1e-6) return BehaviorStatus::kSucceeded;
    double vel = std::sqrt(2 * params_.rotational_acc_lim * remaining);
    vel = std::min(std::max(vel, params_.min_rotational_vel), params_.max_rotational_vel);
    twist_ = {0.0, std::copysign(vel, params_.spin_dist_rad)};
    if (!spin_collision_free(relative_yaw_, twist_.omega_radps, pose)) {
      failure_ = "collision ahead";
      return BehaviorStatus::kFailed;
    }
    return BehaviorStatus::kRunning;
  }
  // BackUp = DriveOnHeading::onCycleUpdate with command_x = -backup_dist, speed = -backup_speed.
  const double distance = std::hypot(pose.x_m - initial_.x_m, pose.y_m - initial_.y_m);
  if (distance >= std::abs(params_.backup_dist_m)) return BehaviorStatus::kSucceeded;
  twist_ = {-std::abs(params_.backup_speed_mps), 0.0};
  if (!backup_collision_free(distance, twist_.v_mps, pose)) {
    failure_ = "collision ahead";
    return BehaviorStatus::kFailed;
  }
  return BehaviorStatus::kRunning;
}

// Spin::isCollisionFree as written: it stops simulating once the simulated turn reaches the turn already done
// (relative_yaw), so the first cycle (relative_yaw 0) checks nothing.
bool Behavior::spin_collision_free(double relative_yaw, double omega, Pose2 pose) const {
  const int max_cycles = static_cast<int>(params_.cycle_frequency_hz * params_.simulate_ahead_time_s);
  const double yaw0 = pose.yaw_rad;
  for (int cycle = 0; cycle < max_cycles; ++cycle) {
    const double change = omega * (cycle / params_.cycle_frequency_hz);
    pose.yaw_rad = yaw0 + change;
    if (std::abs(relative_yaw) - std::abs(change) <= 0.) break;
    if (!collision_free_(pose)) return false;
  }
  return true;
}

// DriveOnHeading::isCollisionFree: along the heading at the commanded speed until the distance left is covered.
bool Behavior::backup_collision_free(double distance, double v, Pose2 pose) const {
  const int max_cycles = static_cast<int>(params_.cycle_frequency_hz * params_.simulate_ahead_time_s);
  const double diff_dist = std::abs(params_.backup_dist_m) - distance;
  const Pose2 init = pose;
  for (int cycle = 0; cycle < max_cycles; ++cycle) {
    const double change = v * (cycle / params_.cycle_frequency_hz);
    pose.x_m = init.x_m + change * std::cos(init.yaw_rad);
    pose.y_m = init.y_m + change * std::sin(init.yaw_rad);
    if (diff_dist - std::abs(change) <= 0.) break;
    if (!collision_free_(pose)) return false;
  }
  return true;
}

}  // namespace stvl::navigation

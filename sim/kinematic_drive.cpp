#include "sim/kinematic_drive.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/enum_names.hpp"

namespace stvl::sim {
namespace {

constexpr EnumName<DriveMode> kDriveModeNames[] = {
    {DriveMode::kPhysics, "physics"}, {DriveMode::kKinematic, "kinematic"}, {DriveMode::kAuto, "auto"}};

constexpr double kSamePoint_m = 1e-6;
constexpr double kSameHeading_rad = 1e-9;

double wrap_angle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

// A trapezoidal (or triangular) speed profile over `distance` (>= 0) with top speed v and ramps a.
struct Ramp {
  double distance, v, a;
  double peak() const { return std::min(v, std::sqrt(distance * a)); }
  double duration() const { return distance <= 0 ? 0.0 : distance / peak() + peak() / a; }
  // Distance covered and speed after t (0 <= t <= duration()).
  std::pair<double, double> at(double t) const {
    const double top = peak(), T = duration(), t_ramp = top / a;
    if (t <= 0) return {0.0, 0.0};
    if (t >= T) return {distance, 0.0};
    if (t < t_ramp) return {0.5 * a * t * t, a * t};
    if (t > T - t_ramp) return {distance - 0.5 * a * (T - t) * (T - t), a * (T - t)};
    return {0.5 * top * t_ramp + top * (t - t_ramp), top};
  }
};

}  // namespace

DriveMode parse_drive_mode(const std::string& text) { return parse_enum(text, kDriveModeNames, "drive"); }
std::string to_string(DriveMode mode) { return enum_name(mode, kDriveModeNames); }

KinematicDrive::KinematicDrive(PathFollowerConfig limits) : limits_(limits) {
  if (!(limits_.decel_mps2 > 0) || !(limits_.max_angular_speed_radps > 0) || !(limits_.angular_decel_radps2 > 0))
    throw std::invalid_argument(
        "kinematic drive: decel_mps2, max_angular_speed_radps and angular_decel_radps2 must be > 0");
}

void KinematicDrive::add_turn(Pose2D& at, double heading_rad, std::vector<Segment>& out) const {
  const double turn = wrap_angle(heading_rad - at.yaw_rad);
  if (std::abs(turn) <= kSameHeading_rad) return;
  out.push_back(
      {at, turn, true, Ramp{std::abs(turn), limits_.max_angular_speed_radps, limits_.angular_decel_radps2}.duration()});
  at.yaw_rad = heading_rad;
}

void KinematicDrive::add_leg(Pose2D& at, const Eigen::Vector2d& to, std::vector<Segment>& out) const {
  const Eigen::Vector2d d = to - Eigen::Vector2d(at.x_m, at.y_m);
  if (d.norm() < kSamePoint_m) return;
  add_turn(at, std::atan2(d.y(), d.x()), out);
  out.push_back({at, d.norm(), false, Ramp{d.norm(), cruise_mps_, limits_.decel_mps2}.duration()});
  at.x_m = to.x(), at.y_m = to.y();
}

void KinematicDrive::set_path(const Path& path, const Pose2D& start, double t0_s) {
  PathFollower(limits_).set_path(path);  // the same rules for waypoints and speed
  if (!std::isfinite(start.x_m + start.y_m + start.yaw_rad) || !std::isfinite(t0_s))
    throw std::invalid_argument("kinematic drive: non-finite start pose or time");
  cruise_mps_ = path.cruise_speed_mps;
  t0_s_ = t0_s;
  loop_ = path.loop;
  segments_.clear();
  const auto& w = path.waypoints_W;
  const Eigen::Vector2d first_leg = w[1] - w[0];
  Pose2D at = start;
  add_leg(at, w.front(), segments_);
  if (loop_) add_turn(at, std::atan2(first_leg.y(), first_leg.x()), segments_);
  lap_begin_ = segments_.size();
  for (std::size_t i = 1; i < w.size(); ++i) add_leg(at, w[i], segments_);
  if (loop_) {  // back to the first waypoint, and turned toward the first leg again: the next lap starts as this one
    add_leg(at, w.front(), segments_);
    add_turn(at, std::atan2(first_leg.y(), first_leg.x()), segments_);
  }
  approach_s_ = lap_s_ = 0;
  for (std::size_t i = 0; i < segments_.size(); ++i) (i < lap_begin_ ? approach_s_ : lap_s_) += segments_[i].duration_s;
  last_turn_s_ = loop_ && segments_.back().turn ? segments_.back().duration_s : 0.0;
}

KinematicDrive::State KinematicDrive::state_in(const Segment& s, double t_s) const {
  State state;
  state.pose = s.from;
  if (s.turn) {
    const auto [angle, rate] =
        Ramp{std::abs(s.length), limits_.max_angular_speed_radps, limits_.angular_decel_radps2}.at(t_s);
    state.pose.yaw_rad = wrap_angle(s.from.yaw_rad + std::copysign(angle, s.length));
    state.twist.omega_radps = std::copysign(rate, s.length);
  } else {
    const auto [distance, speed] = Ramp{s.length, cruise_mps_, limits_.decel_mps2}.at(t_s);
    state.pose.x_m += distance * std::cos(s.from.yaw_rad);
    state.pose.y_m += distance * std::sin(s.from.yaw_rad);
    state.twist.v_mps = speed;
  }
  return state;
}

KinematicDrive::State KinematicDrive::at(double t_s) const {
  if (segments_.empty()) return {};
  double t = std::max(0.0, t_s - t0_s_);
  std::size_t i = 0;
  if (loop_ && t >= approach_s_ && lap_s_ > 0) {
    t = std::fmod(t - approach_s_, lap_s_);
    i = lap_begin_;
  }
  for (; i < segments_.size(); ++i) {
    if (t < segments_[i].duration_s) return state_in(segments_[i], t);
    t -= segments_[i].duration_s;
  }
  const Segment& last = segments_.back();
  return state_in(last, last.duration_s);
}

bool KinematicDrive::finished(double t_s) const {
  return !segments_.empty() && !loop_ && t_s - t0_s_ >= approach_s_ + lap_s_;
}

int KinematicDrive::laps_completed(double t_s) const {
  // A lap ends on arriving at the first waypoint, before the turn toward the first leg.
  if (!loop_ || !(lap_s_ > 0) || t_s - t0_s_ < approach_s_) return 0;
  return static_cast<int>((t_s - t0_s_ - approach_s_ + last_turn_s_) / lap_s_);
}

}  // namespace stvl::sim

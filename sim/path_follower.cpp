#include "sim/path_follower.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace stvl::sim {
namespace {

double wrap_angle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

}  // namespace

PathFollower::PathFollower(PathFollowerConfig config) : config_(config) {
  if (!(config_.lookahead_m > 0) || !(config_.goal_tolerance_m > 0) || !(config_.decel_mps2 > 0) ||
      !(config_.max_angular_speed_radps > 0) || !(config_.angular_decel_radps2 > 0)) {
    throw std::invalid_argument(
        "path follower: lookahead_m, goal_tolerance_m, decel_mps2, "
        "max_angular_speed_radps and angular_decel_radps2 must be > 0");
  }
}

void PathFollower::set_path(const Path& given) {
  Path path = given;
  auto& w = path.waypoints_W;
  if (path.loop) {
    const bool closed = w.size() >= 2 && w.front() == w.back();
    const std::size_t distinct = closed ? w.size() - 1 : w.size();
    if (distinct < 2) {
      throw std::invalid_argument("a looping path needs at least 2 distinct waypoints, got " +
                                  std::to_string(distinct));
    }
    if (!closed) w.push_back(w.front());
  }
  if (w.size() < 2) {
    throw std::invalid_argument("path needs at least 2 waypoints, got " + std::to_string(w.size()));
  }
  if (!(path.cruise_speed_mps > 0) || path.cruise_speed_mps > config_.max_cruise_speed_mps) {
    throw std::invalid_argument("path cruise_speed_mps " + std::to_string(path.cruise_speed_mps) + " outside (0, " +
                                std::to_string(config_.max_cruise_speed_mps) + "]");
  }
  std::vector<double> s_vertex{0.0};
  for (std::size_t i = 0; i < w.size(); ++i) {
    if (!w[i].allFinite()) throw std::invalid_argument("path waypoint " + std::to_string(i) + " is not finite");
    if (i == 0) continue;
    const double len = (w[i] - w[i - 1]).norm();
    if (len < 1e-6)
      throw std::invalid_argument("path waypoints " + std::to_string(i - 1) + " and " + std::to_string(i) +
                                  " coincide");
    s_vertex.push_back(s_vertex.back() + len);
  }
  std::vector<double> s_corner;
  for (std::size_t i = 1; i + 1 < w.size(); ++i) {
    const Eigen::Vector2d a = w[i] - w[i - 1], b = w[i + 1] - w[i];
    const double turn = std::abs(wrap_angle(std::atan2(b.y(), b.x()) - std::atan2(a.y(), a.x())));
    if (turn > config_.corner_angle_rad) s_corner.push_back(s_vertex[i]);
  }
  s_corner.push_back(s_vertex.back());
  path_ = std::move(path);
  s_vertex_ = std::move(s_vertex);
  s_corner_ = std::move(s_corner);
  leg_ = 0;
  s_ = 0.0;
  mode_ = Mode::align;
  finished_ = false;
  laps_ = 0;
}

Eigen::Vector2d PathFollower::point_at(double s) const {
  const auto& w = path_.waypoints_W;
  s = std::clamp(s, 0.0, s_vertex_.back());
  const auto it = std::upper_bound(s_vertex_.begin(), s_vertex_.end(), s);
  const std::size_t i = std::min<std::size_t>(std::max<std::ptrdiff_t>(it - s_vertex_.begin(), 1), w.size() - 1);
  const double t = (s - s_vertex_[i - 1]) / (s_vertex_[i] - s_vertex_[i - 1]);
  return w[i - 1] + std::clamp(t, 0.0, 1.0) * (w[i] - w[i - 1]);
}

double PathFollower::heading_at(double s) const {
  const Eigen::Vector2d d = point_at(s + 1e-3) - point_at(s);
  return std::atan2(d.y(), d.x());
}

double PathFollower::project(const Eigen::Vector2d& p_W, double s_from, double s_to) const {
  const auto& w = path_.waypoints_W;
  double best_s = s_from, best_d2 = (point_at(s_from) - p_W).squaredNorm();
  for (std::size_t i = 1; i < w.size(); ++i) {
    if (s_vertex_[i] < s_from || s_vertex_[i - 1] > s_to) continue;
    const Eigen::Vector2d seg = w[i] - w[i - 1];
    const double len = s_vertex_[i] - s_vertex_[i - 1];
    double s = s_vertex_[i - 1] + std::clamp((p_W - w[i - 1]).dot(seg) / len, 0.0, len);
    s = std::clamp(s, s_from, s_to);
    const double d2 = (point_at(s) - p_W).squaredNorm();
    if (d2 < best_d2) best_d2 = d2, best_s = s;
  }
  return best_s;
}

double PathFollower::cross_track_error_m(const Eigen::Vector2d& p_W) const {
  if (!has_path()) return 0.0;
  return (point_at(project(p_W, 0.0, s_vertex_.back())) - p_W).norm();
}

Twist2D PathFollower::rotate_toward(double heading_rad, double yaw_rad) {
  const double err = wrap_angle(heading_rad - yaw_rad);
  const double speed =
      std::min({config_.max_angular_speed_radps, std::sqrt(2.0 * config_.angular_decel_radps2 * std::abs(err)),
                std::max(0.15, 3.0 * std::abs(err))});
  return Twist2D{0.0, std::copysign(speed, err)};
}

Twist2D PathFollower::update(const Eigen::Vector2d& p_W, double yaw_rad) {
  if (!path_.reverse) return update_forward(p_W, yaw_rad);
  // Backwards: follow the path with the rear as the front (heading yaw + pi); the same turn rate in the world, the
  // linear speed negated.
  const Twist2D t = update_forward(p_W, wrap_angle(yaw_rad + M_PI));
  return Twist2D{-t.v_mps, t.omega_radps};
}

Twist2D PathFollower::update_forward(const Eigen::Vector2d& p_W, double yaw_rad) {
  if (!has_path() || finished_) return {};
  const double leg_start = leg_ == 0 ? 0.0 : s_corner_[leg_ - 1];
  const double leg_end = s_corner_[leg_];

  if (mode_ == Mode::turn_at_corner || mode_ == Mode::align) {
    const Eigen::Vector2d to_goal = point_at(std::min(s_ + config_.lookahead_m, leg_end)) - p_W;
    const double target = mode_ == Mode::align ? std::atan2(to_goal.y(), to_goal.x()) : heading_at(leg_start);
    if (std::abs(wrap_angle(target - yaw_rad)) > config_.heading_tolerance_rad) {
      return rotate_toward(target, yaw_rad);
    }
    mode_ = Mode::track;
  }

  s_ = project(p_W, s_, std::min(leg_end, s_ + 2.0 * config_.lookahead_m));
  const double remaining = leg_end - s_;
  if (remaining < config_.goal_tolerance_m) {
    if (leg_ + 1 == s_corner_.size()) {
      if (!path_.loop) {
        finished_ = true;
        return {};
      }
      // Back at the first waypoint: the next lap starts with a turn toward the first leg.
      ++laps_;
      leg_ = 0;
      s_ = 0.0;
      mode_ = Mode::turn_at_corner;
      return rotate_toward(heading_at(0.0), yaw_rad);
    }
    ++leg_;
    s_ = leg_end;
    mode_ = Mode::turn_at_corner;
    return rotate_toward(heading_at(leg_end), yaw_rad);
  }

  const Eigen::Vector2d goal = point_at(std::min(s_ + config_.lookahead_m, leg_end));
  const Eigen::Vector2d d_W = goal - p_W;
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  const double x_R = c * d_W.x() + s * d_W.y();
  const double y_R = -s * d_W.x() + c * d_W.y();
  if (std::abs(std::atan2(y_R, x_R)) > config_.align_angle_rad) {
    mode_ = Mode::align;
    return rotate_toward(std::atan2(d_W.y(), d_W.x()), yaw_rad);
  }
  const double dist2 = std::max(x_R * x_R + y_R * y_R, 1e-9);
  const double curvature = 2.0 * y_R / dist2;
  double v = std::min(path_.cruise_speed_mps, std::sqrt(2.0 * config_.decel_mps2 * remaining));
  v = std::max(v, config_.min_speed_mps);
  if (std::abs(v * curvature) > config_.max_angular_speed_radps) {
    v = config_.max_angular_speed_radps / std::abs(curvature);
  }
  return Twist2D{v, v * curvature};
}

}  // namespace stvl::sim

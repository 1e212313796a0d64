#include "sim/odometry.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace stvl::sim {

WheelOdometry::WheelOdometry(double wheel_radius_m, double track_width_m, OdometryConfig config)
    : config_(config), rng_(config.seed) {
  if (!(wheel_radius_m > 0) || !(track_width_m > 0)) {
    throw std::invalid_argument("odometry: wheel radius " + std::to_string(wheel_radius_m) + " m and track width " +
                                std::to_string(track_width_m) + " m must be > 0");
  }
  if (!(config.linear_noise_std_mps >= 0) || !(config.angular_noise_std_radps >= 0)) {
    throw std::invalid_argument("odometry: noise std must be >= 0");
  }
  const bool d = config_.drift;
  left_radius_m_ = wheel_radius_m * (1.0 + (d ? config_.left_wheel_radius_error : 0.0));
  right_radius_m_ = wheel_radius_m * (1.0 + (d ? config_.right_wheel_radius_error : 0.0));
  track_m_ = track_width_m * (1.0 + (d ? config_.track_width_error : 0.0));
  if (!(left_radius_m_ > 0) || !(right_radius_m_ > 0) || !(track_m_ > 0)) {
    throw std::invalid_argument("odometry: scale errors make a radius or the track non-positive");
  }
}

// Box-Muller on the raw engine output: identical sequences on every standard library.
double WheelOdometry::gaussian() {
  constexpr double kTwoPi = 6.283185307179586;
  const double u1 = (static_cast<double>(rng_() >> 11) + 1.0) * 0x1.0p-53;
  const double u2 = static_cast<double>(rng_() >> 11) * 0x1.0p-53;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(kTwoPi * u2);
}

void WheelOdometry::update(double left_rate_radps, double right_rate_radps, double dt_s) {
  if (!(dt_s >= 0) || !std::isfinite(left_rate_radps) || !std::isfinite(right_rate_radps)) {
    throw std::invalid_argument("odometry update with dt_s " + std::to_string(dt_s) + " or non-finite rates");
  }
  const double v_left = left_rate_radps * left_radius_m_;
  const double v_right = right_rate_radps * right_radius_m_;
  v_mps_ = 0.5 * (v_left + v_right);
  omega_radps_ = (v_right - v_left) / track_m_;
  if (config_.drift) {
    v_mps_ += config_.linear_noise_std_mps * gaussian();
    omega_radps_ += config_.angular_noise_std_radps * gaussian();
  }
  const double mid_yaw = yaw_rad_ + 0.5 * omega_radps_ * dt_s;
  x_m_ += v_mps_ * dt_s * std::cos(mid_yaw);
  y_m_ += v_mps_ * dt_s * std::sin(mid_yaw);
  yaw_rad_ = std::atan2(std::sin(yaw_rad_ + omega_radps_ * dt_s), std::cos(yaw_rad_ + omega_radps_ * dt_s));
}

void WheelOdometry::reset() {
  x_m_ = y_m_ = yaw_rad_ = v_mps_ = omega_radps_ = 0;
  rng_.seed(config_.seed);
}

Eigen::Isometry3d WheelOdometry::T_odom_base() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad_, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x_m_, y_m_, 0.0);
  return T;
}

}  // namespace stvl::sim

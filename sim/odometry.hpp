#pragma once
// Planar wheel odometry integrated from wheel joint rates. T_odom_base starts at identity
// (REP-105), so T_map_odom = T_world_base * T_odom_base^-1 is the start pose plus the drift.
#include <cstdint>
#include <random>

#include <Eigen/Geometry>

namespace stvl::sim {

struct OdometryConfig {
  bool drift = false;                      // false: the error terms below are ignored and odometry is exact kinematics
  double left_wheel_radius_error = 0.004;  // relative error of the assumed radius, e.g. 0.004 = +0.4 %
  double right_wheel_radius_error = -0.004;
  double track_width_error = 0.01;
  double linear_noise_std_mps = 0.02;     // white noise added to v at every update
  double angular_noise_std_radps = 0.02;  // white noise added to omega at every update
  std::uint64_t seed = 1;
};

class WheelOdometry {
 public:
  WheelOdometry(double wheel_radius_m, double track_width_m, OdometryConfig config = {});

  // Integrates one interval with the wheel rates (rad/s, positive forward) held over dt_s.
  void update(double left_rate_radps, double right_rate_radps, double dt_s);
  void reset();

  Eigen::Isometry3d T_odom_base() const;
  double x_m() const { return x_m_; }
  double y_m() const { return y_m_; }
  double yaw_rad() const { return yaw_rad_; }
  double v_mps() const { return v_mps_; }  // last body twist estimate
  double omega_radps() const { return omega_radps_; }

 private:
  double gaussian();

  double left_radius_m_, right_radius_m_, track_m_;
  OdometryConfig config_;
  std::mt19937_64 rng_;
  double x_m_ = 0, y_m_ = 0, yaw_rad_ = 0, v_mps_ = 0, omega_radps_ = 0;
};

}  // namespace stvl::sim

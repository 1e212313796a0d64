#include "mapping/lidar_frustum.hpp"

#include <cmath>
#include <stdexcept>

#include "mapping/frustum.hpp"

namespace stvl::mapping {

LidarFrustum::LidarFrustum(const Eigen::Isometry3d& T_world_sensor, const ObservationSource& source) {
  source.validate();
  validate_pose(T_world_sensor);
  // The constructor's members (hFOV/2, tan(vFOV/2)^2, min_z^2, max_z^2, hFOV > 6.27) and TransformModel's
  // conjugate orientation.
  half_hfov_rad_ = source.horizontal_fov_rad / 2.0;
  const double tan_half_vfov = std::tan(source.vertical_fov_rad / 2.0);
  tan_half_vfov_sq_ = tan_half_vfov * tan_half_vfov;
  min_sq_m2_ = source.min_z_m * source.min_z_m;
  max_sq_m2_ = source.max_z_m * source.max_z_m;
  padding_m_ = source.vertical_fov_padding_m;
  full_circle_ = source.horizontal_fov_rad > 6.27;
  inverse_orientation_ = Eigen::Quaterniond(T_world_sensor.linear()).conjugate();
  origin_W_ = T_world_sensor.translation();
  const double r = source.max_z_m, h = source.max_z_m * tan_half_vfov + 1e-6;
  for (double x : {-r, r})
    for (double y : {-r, r})
      for (double z : {-h, h}) bounds_W_.extend(T_world_sensor * Eigen::Vector3d(x, y, z));
  bounds_W_.min().array() -= 1e-6;
  bounds_W_.max().array() += 1e-6;
}

bool LidarFrustum::contains(const Eigen::Vector3d& p_W) const {
  const Eigen::Vector3d t = inverse_orientation_ * (p_W - origin_W_);
  const double r_sq = t.x() * t.x() + t.y() * t.y();
  if (r_sq > max_sq_m2_ || r_sq < min_sq_m2_) return false;
  const double v_padded = std::abs(t.z()) + padding_m_;
  if (v_padded * v_padded / r_sq > tan_half_vfov_sq_) return false;  // r = 0: +inf is outside, 0/0 (NaN) inside
  if (full_circle_) return true;
  constexpr double kHalfPi = 1.57079632679489661923;
  if (t.x() > 0.0) return !(std::abs(std::atan(t.y() / t.x())) > half_hfov_rad_);
  return !(std::abs(std::atan(t.x() / t.y())) + kHalfPi > half_hfov_rad_);
}

}  // namespace stvl::mapping

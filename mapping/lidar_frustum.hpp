#pragma once
// STVL's 3D lidar clearing volume (model_type 1: ThreeDimensionalLidarFrustum, ros2 403d9ed, the same in
// noetic-devel 5e06daf), in the sensor frame STVL is given (x forward, z up for a lidar; see
// ObservationSource::sensor_frame). With t the point in that frame (the conjugate quaternion applied to p - origin,
// as STVL does), r^2 = t.x^2 + t.y^2 (the horizontal range, not the 3D one):
//   outside when r^2 > max_z^2 or r^2 < min_z^2;
//   outside when (|t.z| + vertical_fov_padding)^2 / r^2 > tan^2(v/2) (the padding shrinks the cone by metres);
//   unless h > 6.27 rad (full circle): outside when |atan(t.y / t.x)| > h/2 for t.x > 0, and when
//   |atan(t.x / t.y)| + pi/2 > h/2 for t.x <= 0.
// Every comparison strict (the boundary is inside), in double.
#include <Eigen/Geometry>

#include "mapping/config.hpp"

namespace stvl::mapping {

class LidarFrustum {
 public:
  // T_world_sensor: the frame the model is built in. Throws std::invalid_argument for a bad source or pose.
  LidarFrustum(const Eigen::Isometry3d& T_world_sensor, const ObservationSource& source);

  // STVL's IsInside on a point in the world frame.
  bool contains(const Eigen::Vector3d& p_W) const;
  // Conservative: false only when the box lies outside the cylinder's axis-aligned bounds.
  bool may_intersect(const Eigen::AlignedBox3d& box_W) const { return bounds_W_.intersects(box_W); }
  // Axis-aligned box around the cylinder of radius max_z and height 2 max_z tan(v/2) (padded by 1 um).
  const Eigen::AlignedBox3d& bounds_W() const { return bounds_W_; }

 private:
  Eigen::Quaterniond inverse_orientation_;  // STVL's q.conjugate()
  Eigen::Vector3d origin_W_;
  double half_hfov_rad_, tan_half_vfov_sq_, min_sq_m2_, max_sq_m2_, padding_m_;
  bool full_circle_;
  Eigen::AlignedBox3d bounds_W_;
};

}  // namespace stvl::mapping

#pragma once
// A depth camera's clearing frustum in the world frame: 6 planes from the FOV and min_z/max_z.
// T_world_camera is the optical frame (z forward, x right, y down).
#include <Eigen/Geometry>

#include <array>

#include "mapping/config.hpp"

namespace stvl::mapping {

class DepthCameraFrustum {
 public:
  // Throws std::invalid_argument for bad FOV/range or a non-finite pose.
  DepthCameraFrustum(const Eigen::Isometry3d& T_world_camera, double horizontal_fov_rad,
                     double vertical_fov_rad, double min_z_m, double max_z_m);
  DepthCameraFrustum(const Eigen::Isometry3d& T_world_camera, const ObservationSource& source);

  // Boundary points count as inside.
  bool contains(const Eigen::Vector3d& p_W) const;
  // Conservative: false only when the box is certainly outside (some plane has the whole box behind it).
  bool may_intersect(const Eigen::AlignedBox3d& box_W) const;
  // Axis-aligned box around the 8 corners.
  const Eigen::AlignedBox3d& bounds_W() const { return bounds_W_; }

 private:
  std::array<Eigen::Vector4d, 6> planes_W_;  // inside where n.p + d >= 0
  Eigen::AlignedBox3d bounds_W_;
};

// Throws std::invalid_argument when the pose holds NaN/inf or its rotation is not orthonormal.
void validate_pose(const Eigen::Isometry3d& T_world_camera);

}  // namespace stvl::mapping

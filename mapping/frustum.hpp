#pragma once
// A depth camera's clearing frustum in the world frame: 6 planes from the FOV and min_z/max_z.
// T_world_camera is the optical frame (z forward, x right, y down).
//
// Two geometries (FrustumGeometry, mapping/config.hpp):
// - kIdeal (the bench's): the pyramid between z = min_z and z = max_z with |x| <= z tan(h/2), |y| <= z tan(v/2).
// - kStvl: STVL's DepthCameraFrustum (ros2 403d9ed, noetic-devel 5e06daf), built the same way in double: unit
//   corner rays d = Rx(+-v/2) Ry(+-h/2) z, corners d*min_z and d*max_z, outward normals from the cross products
//   of corner differences, anchored at a corner. Near/far planes at min_z/max_z * cos(h/2) cos(v/2),
//   |x| <= z tan(h/2) / cos(v/2) (wider), |y| <= z tan(v/2). p is outside iff dot(n, normalize(p - anchor)) > 0
//   for some plane, tested in STVL's order (top of the +x side, ..., far, near).
#include <Eigen/Geometry>

#include <array>

#include "mapping/config.hpp"

namespace stvl::mapping {

class DepthCameraFrustum {
 public:
  // Throws std::invalid_argument for bad FOV/range or a non-finite pose.
  DepthCameraFrustum(const Eigen::Isometry3d& T_world_camera, double horizontal_fov_rad, double vertical_fov_rad,
                     double min_z_m, double max_z_m, FrustumGeometry geometry = FrustumGeometry::kIdeal);
  DepthCameraFrustum(const Eigen::Isometry3d& T_world_camera, const ObservationSource& source,
                     FrustumGeometry geometry = FrustumGeometry::kIdeal);

  FrustumGeometry geometry() const { return geometry_; }
  // Boundary points count as inside.
  bool contains(const Eigen::Vector3d& p_W) const;
  // Conservative: false only when the box is certainly outside (some plane has the whole box behind it, with a
  // margin of 1 um for kStvl so that rounding in contains()'s normalisation never hides a point it keeps).
  bool may_intersect(const Eigen::AlignedBox3d& box_W) const;
  // Axis-aligned box around the 8 corners (kStvl: padded by the same margin).
  const Eigen::AlignedBox3d& bounds_W() const { return bounds_W_; }

 private:
  // The constructor's two geometries: planes, anchors (kStvl) and bounds from the pose and the validated source.
  void build_stvl(const Eigen::Isometry3d& T_world_camera, double horizontal_fov_rad, double vertical_fov_rad,
                  double min_z_m, double max_z_m);
  void build_ideal(const Eigen::Isometry3d& T_world_camera, double horizontal_fov_rad, double vertical_fov_rad,
                   double min_z_m, double max_z_m);
  FrustumGeometry geometry_;
  std::array<Eigen::Vector4d, 6> planes_W_;  // inside where n.p + d >= 0 (kStvl: -outward normal, for culling)
  // kStvl only: STVL's outward unit normals and anchor points, in the world frame.
  std::array<Eigen::Vector3d, 6> stvl_normals_W_;
  std::array<Eigen::Vector3d, 6> stvl_anchors_W_;
  double cull_margin_m_ = 0.0;
  Eigen::AlignedBox3d bounds_W_;
};

// Throws std::invalid_argument when the pose holds NaN/inf or its rotation is not orthonormal.
void validate_pose(const Eigen::Isometry3d& T_world_camera);

}  // namespace stvl::mapping

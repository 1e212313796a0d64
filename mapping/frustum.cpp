#include "mapping/frustum.hpp"

#include <cmath>
#include <stdexcept>

namespace stvl::mapping {

void validate_pose(const Eigen::Isometry3d& T_world_camera) {
  if (!T_world_camera.matrix().allFinite())
    throw std::invalid_argument("T_world_camera holds a non-finite value");
  const Eigen::Matrix3d R = T_world_camera.linear();
  const double error = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (error > 1e-6 || R.determinant() < 0.0)
    throw std::invalid_argument("T_world_camera rotation is not a proper rotation (|R^T R - I| = " +
                                std::to_string(error) + ")");
}

DepthCameraFrustum::DepthCameraFrustum(const Eigen::Isometry3d& T_world_camera, const ObservationSource& source)
    : DepthCameraFrustum(T_world_camera, source.horizontal_fov_rad, source.vertical_fov_rad, source.min_z_m,
                         source.max_z_m) {}

DepthCameraFrustum::DepthCameraFrustum(const Eigen::Isometry3d& T_world_camera, double horizontal_fov_rad,
                                       double vertical_fov_rad, double min_z_m, double max_z_m) {
  ObservationSource check;
  check.horizontal_fov_rad = horizontal_fov_rad;
  check.vertical_fov_rad = vertical_fov_rad;
  check.min_z_m = min_z_m;
  check.max_z_m = max_z_m;
  check.validate();
  validate_pose(T_world_camera);

  const double ch = std::cos(horizontal_fov_rad / 2), sh = std::sin(horizontal_fov_rad / 2);
  const double cv = std::cos(vertical_fov_rad / 2), sv = std::sin(vertical_fov_rad / 2);
  const std::array<Eigen::Vector4d, 6> planes_C = {
      Eigen::Vector4d(0, 0, 1, -min_z_m),   // near
      Eigen::Vector4d(0, 0, -1, max_z_m),   // far
      Eigen::Vector4d(-ch, 0, sh, 0),     // right: x <= z tan(h/2)
      Eigen::Vector4d(ch, 0, sh, 0),      // left
      Eigen::Vector4d(0, -cv, sv, 0),     // bottom (y down)
      Eigen::Vector4d(0, cv, sv, 0),      // top
  };
  const Eigen::Matrix3d R = T_world_camera.linear();
  const Eigen::Vector3d origin_W = T_world_camera.translation();
  for (std::size_t i = 0; i < planes_C.size(); ++i) {
    const Eigen::Vector3d n_W = R * planes_C[i].head<3>();
    planes_W_[i] << n_W, planes_C[i][3] - n_W.dot(origin_W);
  }
  const double th = std::tan(horizontal_fov_rad / 2), tv = std::tan(vertical_fov_rad / 2);
  for (double z_m : {min_z_m, max_z_m})
    for (double sx : {-1.0, 1.0})
      for (double sy : {-1.0, 1.0})
        bounds_W_.extend(T_world_camera * Eigen::Vector3d(sx * z_m * th, sy * z_m * tv, z_m));
}

bool DepthCameraFrustum::contains(const Eigen::Vector3d& p_W) const {
  for (const auto& plane : planes_W_)
    if (plane.head<3>().dot(p_W) + plane[3] < 0.0) return false;
  return true;
}

bool DepthCameraFrustum::may_intersect(const Eigen::AlignedBox3d& box_W) const {
  if (!bounds_W_.intersects(box_W)) return false;
  for (const auto& plane : planes_W_) {
    Eigen::Vector3d farthest;
    for (int a = 0; a < 3; ++a) farthest[a] = plane[a] >= 0.0 ? box_W.max()[a] : box_W.min()[a];
    if (plane.head<3>().dot(farthest) + plane[3] < 0.0) return false;
  }
  return true;
}

}  // namespace stvl::mapping

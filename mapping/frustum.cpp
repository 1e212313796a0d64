#include "mapping/frustum.hpp"

#include <cmath>
#include <stdexcept>

namespace stvl::mapping {

void validate_pose(const Eigen::Isometry3d& T_world_camera) {
  if (!T_world_camera.matrix().allFinite()) throw std::invalid_argument("T_world_camera holds a non-finite value");
  const Eigen::Matrix3d R = T_world_camera.linear();
  const double error = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (error > 1e-6 || R.determinant() < 0.0)
    throw std::invalid_argument(
        "T_world_camera rotation is not a proper rotation (|R^T R - I| = " + std::to_string(error) + ")");
}

namespace {

constexpr double kStvlCullMargin_m = 1e-6;

// STVL's dot product (DepthCameraFrustum::Dot): x, y, z summed left to right.
inline double stvl_dot(const Eigen::Vector3d& n, const Eigen::Vector3d& p) {
  return n[0] * p[0] + n[1] * p[1] + n[2] * p[2];
}

// STVL's frustum corners in the camera frame (ComputePlaneNormals): the four corner rays, Y rotation first then X,
// as Affine3d products on doubles; pt[2k] at min_z_m, pt[2k + 1] at max_z_m.
std::array<Eigen::Vector3d, 8> stvl_corners_C(double horizontal_fov_rad, double vertical_fov_rad, double min_z_m,
                                              double max_z_m) {
  const Eigen::Vector3d Z = Eigen::Vector3d::UnitZ();
  auto ray = [&](double sign_v, double sign_h) -> Eigen::Vector3d {
    const Eigen::Affine3d rx(Eigen::AngleAxisd(sign_v * vertical_fov_rad / 2., Eigen::Vector3d::UnitX()));
    const Eigen::Affine3d ry(Eigen::AngleAxisd(sign_h * horizontal_fov_rad / 2., Eigen::Vector3d::UnitY()));
    return rx * ry * Z;
  };
  const std::array<Eigen::Vector3d, 4> rays = {ray(+1, +1), ray(-1, +1), ray(-1, -1), ray(+1, -1)};
  std::array<Eigen::Vector3d, 8> pt;
  for (std::size_t k = 0; k < 4; ++k) {
    pt[2 * k] = rays[k] * min_z_m;
    pt[2 * k + 1] = rays[k] * max_z_m;
  }
  return pt;
}

}  // namespace

DepthCameraFrustum::DepthCameraFrustum(const Eigen::Isometry3d& T_world_camera, const ObservationSource& source,
                                       FrustumGeometry geometry)
    : DepthCameraFrustum(T_world_camera, source.horizontal_fov_rad, source.vertical_fov_rad, source.min_z_m,
                         source.max_z_m, geometry) {}

DepthCameraFrustum::DepthCameraFrustum(const Eigen::Isometry3d& T_world_camera, double horizontal_fov_rad,
                                       double vertical_fov_rad, double min_z_m, double max_z_m,
                                       FrustumGeometry geometry)
    : geometry_(geometry) {
  ObservationSource check;
  check.horizontal_fov_rad = horizontal_fov_rad;
  check.vertical_fov_rad = vertical_fov_rad;
  check.min_z_m = min_z_m;
  check.max_z_m = max_z_m;
  check.validate();
  validate_pose(T_world_camera);
  if (geometry != FrustumGeometry::kIdeal && geometry != FrustumGeometry::kStvl)
    throw std::invalid_argument("frustum geometry " + std::to_string(static_cast<int>(geometry)) + " is unknown");
  if (geometry == FrustumGeometry::kStvl)
    build_stvl(T_world_camera, horizontal_fov_rad, vertical_fov_rad, min_z_m, max_z_m);
  else build_ideal(T_world_camera, horizontal_fov_rad, vertical_fov_rad, min_z_m, max_z_m);
}

void DepthCameraFrustum::build_stvl(const Eigen::Isometry3d& T_world_camera, double horizontal_fov_rad,
                                    double vertical_fov_rad, double min_z_m, double max_z_m) {
  const Eigen::Matrix3d R = T_world_camera.linear();
  const std::array<Eigen::Vector3d, 8> pt = stvl_corners_C(horizontal_fov_rad, vertical_fov_rad, min_z_m, max_z_m);
  auto unit = [](Eigen::Vector3d v) {
    v.normalize();
    return v;
  };
  const Eigen::Vector3d far_C = unit((pt[7] - pt[5]).cross(pt[1] - pt[7]));
  const std::array<Eigen::Vector3d, 6> normals_C = {unit((pt[3] - pt[1]).cross(pt[1] - pt[0])),
                                                    unit((pt[5] - pt[3]).cross(pt[3] - pt[2])),
                                                    unit((pt[7] - pt[5]).cross(pt[5] - pt[4])),
                                                    unit((pt[1] - pt[7]).cross(pt[7] - pt[6])),
                                                    far_C,
                                                    -far_C};
  const std::array<Eigen::Vector3d, 6> anchors_C = {pt[0], pt[2], pt[4], pt[6], pt[7], pt[2]};
  for (std::size_t i = 0; i < 6; ++i) {
    stvl_normals_W_[i] = unit(R * normals_C[i]);  // VectorWithPt3D::TransformFrames
    stvl_anchors_W_[i] = T_world_camera * anchors_C[i];
    planes_W_[i] << -stvl_normals_W_[i], stvl_normals_W_[i].dot(stvl_anchors_W_[i]);
  }
  cull_margin_m_ = kStvlCullMargin_m;
  for (const Eigen::Vector3d& corner_C : pt) bounds_W_.extend(T_world_camera * corner_C);
  bounds_W_.min().array() -= kStvlCullMargin_m;
  bounds_W_.max().array() += kStvlCullMargin_m;
}

void DepthCameraFrustum::build_ideal(const Eigen::Isometry3d& T_world_camera, double horizontal_fov_rad,
                                     double vertical_fov_rad, double min_z_m, double max_z_m) {
  const Eigen::Matrix3d R = T_world_camera.linear();
  const Eigen::Vector3d origin_W = T_world_camera.translation();
  const double ch = std::cos(horizontal_fov_rad / 2), sh = std::sin(horizontal_fov_rad / 2);
  const double cv = std::cos(vertical_fov_rad / 2), sv = std::sin(vertical_fov_rad / 2);
  const std::array<Eigen::Vector4d, 6> planes_C = {
      Eigen::Vector4d(0, 0, 1, -min_z_m),  // near
      Eigen::Vector4d(0, 0, -1, max_z_m),  // far
      Eigen::Vector4d(-ch, 0, sh, 0),      // right: x <= z tan(h/2)
      Eigen::Vector4d(ch, 0, sh, 0),       // left
      Eigen::Vector4d(0, -cv, sv, 0),      // bottom (y down)
      Eigen::Vector4d(0, cv, sv, 0),       // top
  };
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
  if (geometry_ == FrustumGeometry::kStvl) {
    for (std::size_t i = 0; i < 6; ++i) {  // DepthCameraFrustum::IsInside
      Eigen::Vector3d delta(p_W[0] - stvl_anchors_W_[i][0], p_W[1] - stvl_anchors_W_[i][1],
                            p_W[2] - stvl_anchors_W_[i][2]);
      delta.normalize();  // a zero vector stays zero: on the anchor counts as inside
      if (stvl_dot(stvl_normals_W_[i], delta) > 0.) return false;
    }
    return true;
  }
  for (const auto& plane : planes_W_)
    if (plane.head<3>().dot(p_W) + plane[3] < 0.0) return false;
  return true;
}

bool DepthCameraFrustum::may_intersect(const Eigen::AlignedBox3d& box_W) const {
  if (!bounds_W_.intersects(box_W)) return false;
  for (const auto& plane : planes_W_) {
    Eigen::Vector3d farthest;
    for (int a = 0; a < 3; ++a) farthest[a] = plane[a] >= 0.0 ? box_W.max()[a] : box_W.min()[a];
    if (plane.head<3>().dot(farthest) + plane[3] < -cull_margin_m_) return false;
  }
  return true;
}

}  // namespace stvl::mapping

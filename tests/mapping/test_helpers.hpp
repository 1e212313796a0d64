#pragma once
#include <Eigen/Geometry>

#include <vector>

#include "mapping/config.hpp"
#include "mapping/voxel_map.hpp"

namespace stvl::mapping::test {

// A voxel size representable in float, so that boundaries are exact, and a config with it in our arithmetic
// (floor keys, the ideal frustum, the costmap after the marks), whose boundaries are the textbook ones;
// test_stvl_geometry.cpp pins STVL's.
constexpr double kExactVoxel = 0.125;
inline StvlConfig exact_config() {
  StvlConfig config;
  config.voxel_size_m = kExactVoxel;
  config.mark_rounding = MarkRounding::kFloor;
  config.frustum_geometry = FrustumGeometry::kIdeal;
  config.costmap_timing = CostmapTiming::kAfterMark;
  return config;
}

// Optical frame at position_W looking along +x of the world (z forward, x right = -y_W, y down = -z_W).
inline Eigen::Isometry3d camera_looking_along_x(const Eigen::Vector3d& position_W, double yaw = 0.0) {
  Eigen::Matrix3d R_base_optical;
  R_base_optical << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_base_optical;
  T.translation() = position_W;
  return T;
}

inline ObservationSource wide_source() {
  ObservationSource source;
  source.marking = true;
  source.clearing = true;
  source.obstacle_range_m = 100.0;
  source.min_obstacle_height_m = -100.0;
  source.max_obstacle_height_m = 100.0;
  source.horizontal_fov_rad = 1.2;
  source.vertical_fov_rad = 1.0;
  source.min_z_m = 0.1;
  source.max_z_m = 10.0;
  return source;
}

inline Eigen::Matrix3Xf cloud(const std::vector<Eigen::Vector3f>& points) {
  Eigen::Matrix3Xf out(3, static_cast<Eigen::Index>(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i) out.col(static_cast<Eigen::Index>(i)) = points[i];
  return out;
}

inline bool same_voxels(const std::vector<Voxel>& a, const std::vector<Voxel>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].key != b[i].key || a[i].time_s != b[i].time_s) return false;
  return true;
}

}  // namespace stvl::mapping::test

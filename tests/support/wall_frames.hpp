#pragma once
// Frames of a flat wall seen by a small camera, made without a simulator: what the sensing and the layer take from
// a recording. The camera sits at (0, 0, 1) m looking along +x (optical z = world x, optical x = world -y,
// optical y = world -z).
#include "pipeline/config.hpp"
#include "pipeline/frame.hpp"
#include "tests/support/fixture.hpp"

namespace stvl::test {

inline Eigen::Isometry3d camera_along_x() { return looking_along_x({0, 0, 1}); }

// One 64 x 48 camera (hfov 1 rad, 0.1 .. 10 m, 30 Hz) with one source that marks and clears to 5 m, no filter,
// 0.1 m voxels, the bench's floor rounding and ideal frustum.
inline pipeline::PipelineConfig small_config(mapping::ClearingMode mode) {
  pipeline::PipelineConfig config;
  pipeline::CameraConfig& camera = config.cameras.front();
  camera.intrinsics = sensors::CameraIntrinsics::from_hfov(64, 48, 1.0, 0.1, 10.0, 30.0);
  auto& source = camera.sources.front().params;
  source.clearing = true;
  source.obstacle_range_m = 5.0;
  source.max_obstacle_height_m = 3.0;
  source.max_z_m = 5.0;
  source.horizontal_fov_rad = camera.intrinsics.hfov_rad();
  source.vertical_fov_rad = camera.intrinsics.vfov_rad();
  config.filter.type = filter::FilterType::kNone;
  config.map.voxel_size_m = 0.1;
  config.map.clearing_mode = mode;
  // With STVL's mark rounding the bottom rows' voxels sit one voxel lower (its z shift), below every ray of the
  // next frame, and stay (tests/mapping/test_stvl_geometry.cpp pins that arithmetic).
  config.map.mark_rounding = mapping::MarkRounding::kFloor;
  config.map.frustum_geometry = mapping::FrustumGeometry::kIdeal;
  return config;
}

// Camera 0's frame at time_s: every pixel at depth_m (0: no returns).
inline pipeline::Frame wall_frame(const pipeline::PipelineConfig& config, double depth_m, double time_s) {
  pipeline::Frame f;
  f.time_s = time_s;
  f.T_world_camera = camera_along_x();
  const auto& k = config.cameras.front().intrinsics;
  f.depth = sensors::DepthImage(k.width, k.height);
  for (float& d : f.depth.depth_m) d = static_cast<float>(depth_m);
  return f;
}

}  // namespace stvl::test

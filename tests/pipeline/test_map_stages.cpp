// MapStages alone, on depth images made here (no simulator): what the replay of recordings runs.
#include "pipeline/map_stages.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "tests/support/fixture.hpp"

namespace stvl::pipeline {
namespace {

// A camera at (0, 0, 1) m looking along +x (optical z = world x, optical x = world -y, optical y = world -z).
Eigen::Isometry3d camera_along_x() { return test::looking_along_x({0, 0, 1}); }

PipelineConfig small_config(mapping::ClearingMode mode) {
  PipelineConfig config;
  CameraConfig& camera = config.cameras.front();
  camera.intrinsics = sensors::CameraIntrinsics::from_hfov(64, 48, 1.0, 0.1, 10.0, 30.0);
  camera.sources.front().params.clearing = true;
  camera.sources.front().params.obstacle_range_m = 5.0;
  camera.sources.front().params.max_obstacle_height_m = 3.0;
  camera.sources.front().params.max_z_m = 5.0;
  camera.sources.front().params.horizontal_fov_rad = camera.intrinsics.hfov_rad();
  camera.sources.front().params.vertical_fov_rad = camera.intrinsics.vfov_rad();
  config.filter.type = filter::FilterType::kNone;
  config.map.voxel_size_m = 0.1;
  config.map.clearing_mode = mode;
  // Our arithmetic: with STVL's mark rounding the bottom rows' voxels sit one voxel lower (its z shift), below
  // every ray of the next frame, and stay (test_stvl_geometry.cpp pins that arithmetic).
  config.map.mark_rounding = mapping::MarkRounding::kFloor;
  config.map.frustum_geometry = mapping::FrustumGeometry::kIdeal;
  return config;
}

FrameResult wall_frame(const PipelineConfig& config, double depth_m, double time_s) {
  FrameResult f;
  f.time_s = time_s;
  f.T_world_camera = camera_along_x();
  const auto& k = config.cameras.front().intrinsics;
  f.depth = sensors::DepthImage(k.width, k.height);
  for (float& d : f.depth.depth_m) d = static_cast<float>(depth_m);
  return f;
}

const MapStages::CamerasNow kOneCamera{[](std::size_t) { return camera_along_x(); },
                                       [](std::size_t) { return std::numeric_limits<double>::infinity(); }};

TEST(MapStages, MarksAWallSeenInARecordedImage) {
  const PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
  MapStages stages(config);
  FrameResult f = wall_frame(config, 2.0, 0.0);
  stages.sense(f);
  EXPECT_EQ(f.point_count, 64 * 48);
  EXPECT_EQ(f.marking_W.cols(), 64 * 48);  // no filter, no passthrough
  EXPECT_TRUE(f.edge_filtered_depth.depth_m.empty());
  stages.update(f, kOneCamera);
  ASSERT_FALSE(stages.map().empty());
  for (const VoxelKey& key : stages.map().voxel_keys())
    EXPECT_NEAR(stages.map().center_of(key).x(), 2.0, 0.051) << key.x << " " << key.y << " " << key.z;
  EXPECT_EQ(stages.source_status(0.0).size(), 1u);
}

TEST(MapStages, RaycastClearingRemovesAWallThatMovedAway) {
  const PipelineConfig config = small_config(mapping::ClearingMode::kRaycast);
  MapStages stages(config);
  FrameResult near = wall_frame(config, 2.0, 0.0);
  stages.sense(near);
  stages.update(near, kOneCamera);
  const std::size_t at_two = stages.map().size();
  FrameResult far = wall_frame(config, 3.0, 0.1);
  stages.sense(far);
  stages.update(far, kOneCamera);
  EXPECT_GT(far.cleared_keys.size(), at_two / 2);  // the rays to the wall at 3 m pass through the old one
  for (const VoxelKey& key : stages.map().voxel_keys())
    EXPECT_GT(stages.map().center_of(key).x(), 2.5) << "a voxel of the old wall was left";
}

}  // namespace
}  // namespace stvl::pipeline

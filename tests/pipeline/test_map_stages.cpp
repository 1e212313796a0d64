// MapStages alone, on depth images made here (no simulator): what the replay of recordings runs.
#include "pipeline/map_stages.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <vector>

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

// nav2's update_frequency 5 Hz and a 15 Hz camera: STVL updates at 0, 0.2, 0.4 s, each with the newest reading of
// each buffer (persistence 0); the frames at 1/15 and 2/15 s are never marked.
TEST(MapStages, UpdatesAtTheCostmapsFrequencyTakeTheNewestReading) {
  PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
  config.map.update_frequency_hz = 5.0;
  MapStages stages(config);
  const double walls_m[] = {2.0, 3.0, 4.0, 0.0};  // the last frame sees nothing
  std::vector<bool> updated;
  for (int k = 0; k < 4; ++k) {
    FrameResult f = wall_frame(config, walls_m[k], k / 15.0);
    stages.sense(f);
    stages.update(f, kOneCamera);
    updated.push_back(f.map_updated);
  }
  EXPECT_EQ(updated, (std::vector<bool>{true, false, false, true}));
  ASSERT_FALSE(stages.map().empty());
  for (const VoxelKey& key : stages.map().voxel_keys())
    EXPECT_LT(stages.map().center_of(key).x(), 2.5) << "a wall of a frame between updates was marked";
}

// STVL's layer updates at every tick of the costmap's clock, frames or not. A 10 Hz camera at 4 Hz: the tick at
// 0.25 s runs when the frame at 0.3 s arrives, at its own time, with the newest reading then (the frame at 0.2 s);
// a camera that stops is applied again at every tick (persistence 0 keeps its last reading).
TEST(MapStages, UpdatesAtEveryTickBetweenFramesAtTheTicksTime) {
  PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
  config.map.update_frequency_hz = 4.0;
  config.map.voxel_decay_s = 100.0;
  MapStages stages(config);
  const double walls_m[] = {2.0, 3.0, 4.0, 0.0};
  std::vector<std::vector<double>> update_times;
  for (int k = 0; k < 4; ++k) {
    FrameResult f = wall_frame(config, walls_m[k], k / 10.0);
    stages.sense(f);
    stages.update(f, kOneCamera);
    update_times.emplace_back();
    for (const auto& u : f.updates) update_times.back().push_back(u.time_s);
    EXPECT_EQ(f.map_updated, !f.updates.empty());
    if (k == 3) {
      ASSERT_EQ(f.updates.size(), 1u);
      ASSERT_EQ(f.updates[0].applied_readings.size(), 1u);
      EXPECT_DOUBLE_EQ(f.updates[0].applied_readings[0].reading->time_s, 0.2);
      EXPECT_EQ(f.reapplied_readings, 1u);
    }
  }
  EXPECT_EQ(update_times, (std::vector<std::vector<double>>{{0.0}, {}, {}, {0.25}}));
  std::size_t at_tick = 0;
  for (const VoxelKey& key : stages.map().voxel_keys()) {
    const double x = stages.map().center_of(key).x(), t = *stages.map().lookup(stages.map().center_of(key));
    EXPECT_FALSE(std::abs(x - 3.0) < 0.2) << "the frame at 0.1 s fell between ticks and was marked";
    if (std::abs(t - 0.25) < 1e-12) {
      ++at_tick;
      EXPECT_NEAR(x, 4.0, 0.11) << "a voxel marked at the tick not from the newest reading";
    }
  }
  EXPECT_GT(at_tick, 100u);

  // The camera stops after 0.3 s and comes back at 1.3 s: ticks 0.5, 0.75, 1.0 and 1.25 apply its last reading.
  FrameResult back = wall_frame(config, 2.0, 1.3);
  stages.sense(back);
  stages.update(back, kOneCamera);
  std::vector<double> times;
  for (const auto& u : back.updates) times.push_back(u.time_s);
  EXPECT_EQ(times, (std::vector<double>{0.5, 0.75, 1.0, 1.25}));
  EXPECT_EQ(back.reapplied_readings, 4u);
}

// STVL counts every voxel of a column toward its cell; the marking band on the voxel centres is ours.
TEST(MapStages, CostmapBandIsOursAndOff) {
  PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
  config.cameras.front().sources.front().params.min_obstacle_height_m = 0.1;
  mapping::CostmapOptions stvl = costmap_options(config, Eigen::Isometry3d::Identity());
  EXPECT_TRUE(std::isinf(stvl.min_obstacle_height_m) && stvl.min_obstacle_height_m < 0);
  EXPECT_TRUE(std::isinf(stvl.max_obstacle_height_m) && stvl.max_obstacle_height_m > 0);
  config.map.costmap_band = mapping::CostmapBand::kMarkingBand;
  const mapping::CostmapOptions ours = costmap_options(config, Eigen::Isometry3d::Identity());
  EXPECT_DOUBLE_EQ(ours.min_obstacle_height_m, 0.1);
  EXPECT_DOUBLE_EQ(ours.max_obstacle_height_m, 3.0);
}

// Two cameras on one pose whose frames share a time, in frustum mode: the voxel times after one update at t = 1 s
// of every voxel the wall at t = 0 left (the second frame sees nothing).
std::map<VoxelKey, double> times_after_shared_instant(mapping::UpdateGrouping grouping) {
  PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
  config.map.update_grouping = grouping;
  config.map.voxel_decay_s = 100.0;
  config.cameras.front().sources.front().params.decay_acceleration_per_s3 = 6.0;  // 1 s of age: 1 s more
  config.cameras.front().name = config.cameras.front().sources.front().name = "a";
  CameraConfig b = config.cameras.front();
  b.name = b.sources.front().name = "b";
  config.cameras.push_back(b);
  MapStages stages(config);
  const auto next_at = [](double a_s, double b_s) {
    return MapStages::CamerasNow{[](std::size_t) { return camera_along_x(); },
                                 [=](std::size_t c) { return c == 0 ? a_s : b_s; }};
  };
  FrameResult wall = wall_frame(config, 2.0, 0.0);
  stages.sense(wall);
  stages.update(wall, next_at(1.0, 1.0));  // camera b has no frame at 0
  EXPECT_TRUE(wall.map_updated);
  FrameResult first = wall_frame(config, 0.0, 1.0);  // no returns: the frustum clears, nothing marks
  stages.sense(first);
  stages.update(first, next_at(2.0, 1.0));  // camera b's frame at 1 s follows
  FrameResult second = wall_frame(config, 0.0, 1.0);
  second.camera_index = 1;
  stages.sense(second);
  stages.update(second, next_at(2.0, 2.0));
  EXPECT_TRUE(second.map_updated);
  EXPECT_EQ(first.map_updated, grouping == mapping::UpdateGrouping::kCameraFrame);
  std::map<VoxelKey, double> times;
  for (const VoxelKey& key : stages.map().voxel_keys()) times[key] = *stages.map().lookup(stages.map().center_of(key));
  return times;
}

// STVL's layer clears with every source's frustum in one pass (the first frustum holding a voxel accelerates it,
// once), then marks: a voxel in both cameras' frustums at one instant ages 1./6 * 6 * 1^3 = 1 s more, not twice.
TEST(MapStages, CamerasSharingATimeMakeOneUpdate) {
  const auto instant = times_after_shared_instant(mapping::UpdateGrouping::kInstant);
  // Ours, one update per camera frame: the second frame at the same time accelerates it again, with the age the
  // first left (1 - (-1) = 2 s): 1./6 * 6 * 8 = 8 s more.
  const auto per_frame = times_after_shared_instant(mapping::UpdateGrouping::kCameraFrame);
  ASSERT_EQ(per_frame.size(), instant.size());
  std::size_t accelerated = 0;
  for (const auto& [key, t] : instant) {
    ASSERT_EQ(per_frame.count(key), 1u);
    if (t == 0.0) {  // a wall voxel whose centre lies outside the frustum: neither accelerates it
      EXPECT_EQ(per_frame.at(key), 0.0);
      continue;
    }
    ++accelerated;
    EXPECT_DOUBLE_EQ(t, -1.0);  // marked at 0, accelerated by 1 s once
    EXPECT_DOUBLE_EQ(per_frame.at(key), -9.0);
  }
  EXPECT_GT(accelerated, instant.size() / 2);
}

// STVL's buffer with `filter: voxel` (PCL's VoxelGrid with the band as z limits): the band first, then the leaves.
// Ours decimates the whole cloud and bands the centroids. A wall at 2 m from z 0.23 to 1.77 m, leaves of 0.4 m,
// band [0.9, 1.3]: the leaf row z [1.2, 1.6) has its centroid at about 1.4 m (out of band) for ours, while its
// in-band points alone (z 1.2..1.3) give a centroid inside the band for STVL's order.
TEST(MapStages, StvlVoxelFilterBandsBeforeTheLeaves) {
  std::size_t marking[2] = {0, 0};
  for (const bool band_first : {false, true}) {
    PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
    config.filter.type = filter::FilterType::kVoxel;
    config.filter.voxel.voxel_size_m = 0.4;
    config.filter.passthrough_enabled = true;
    config.filter.passthrough = {0.9, 1.3};
    config.filter.band_before_decimation = band_first;
    MapStages stages(config);
    FrameResult f = wall_frame(config, 2.0, 0.0);
    stages.sense(f);
    for (Eigen::Index i = 0; i < f.marking_W.cols(); ++i) {
      EXPECT_GE(f.marking_W(2, i), 0.9f);
      EXPECT_LE(f.marking_W(2, i), 1.3f);
    }
    if (band_first) {
      EXPECT_EQ(f.decimated_W, f.marking_W);  // what marks also clears
    } else {
      EXPECT_GT(f.decimated_W.cols(), f.marking_W.cols());  // the whole wall decimated
    }
    marking[band_first] = static_cast<std::size_t>(f.marking_W.cols());
  }
  EXPECT_GT(marking[1], marking[0]);  // the leaf row at 1.2..1.6 m marks only in STVL's order
}

// STVL's relative filters (z_reference_frame base_link): the band's z is base_link's. The wall at 2 m spans world
// z 1 +- 0.802 m; with the robot's base 0.5 m up (on a platform) the band 0.9..1.3 m in base_link is world z
// 1.4..1.8, in the world's z it is 0.9..1.3.
TEST(MapStages, RelativeBandIsInBaseLinksZ) {
  for (const auto frame : {mapping::ZReference::kGlobal, mapping::ZReference::kBaseLink}) {
    PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
    auto& source = config.cameras.front().sources.front().params;
    source.min_obstacle_height_m = 0.9;
    source.max_obstacle_height_m = 1.3;
    source.z_reference = frame;
    MapStages stages(config);
    FrameResult f = wall_frame(config, 2.0, 0.0);
    f.T_world_base = Eigen::Translation3d(0.0, 0.0, 0.5) * Eigen::Isometry3d::Identity();
    stages.sense(f);
    stages.update(f, kOneCamera);
    const double lo = frame == mapping::ZReference::kGlobal ? 0.9 : 1.4, hi = lo + 0.4;
    ASSERT_FALSE(stages.map().empty());
    double top = -1.0, bottom = 9.0;
    for (const VoxelKey& key : stages.map().voxel_keys()) {
      top = std::max(top, stages.map().center_of(key).z());
      bottom = std::min(bottom, stages.map().center_of(key).z());
    }
    EXPECT_NEAR(bottom, lo + 0.05, 0.051) << mapping::to_string(frame);  // voxels of 0.1 m
    EXPECT_NEAR(top, hi - 0.05, 0.051) << mapping::to_string(frame);
    if (frame == mapping::ZReference::kGlobal) {
      EXPECT_EQ(f.marking_B.cols(), 0);
      continue;
    }
    // What marks went into base_link and back, each in float as tf2's doTransform does.
    ASSERT_EQ(f.marking_B.cols(), f.marking_W.cols());
    const Eigen::Matrix3f R = f.T_world_base.linear().cast<float>();
    const Eigen::Vector3f t = f.T_world_base.translation().cast<float>();
    for (Eigen::Index i = 0; i < f.marking_W.cols(); ++i)
      ASSERT_EQ(Eigen::Vector3f(R * f.marking_B.col(i) + t), Eigen::Vector3f(f.marking_W.col(i))) << i;
    // The buffer cloud of the source: the band on base_link's z, then as marked.
    SourceReading reading;
    reading.marking_W = f.marking_W;
    reading.marking_B = f.marking_B;
    const Eigen::Matrix3Xf banded = source_marking_W(reading, source);
    ASSERT_GT(banded.cols(), 0);
    for (Eigen::Index i = 0; i < banded.cols(); ++i) {
      EXPECT_GE(banded(2, i), 1.4f - 1e-6f);
      EXPECT_LE(banded(2, i), 1.8f + 1e-6f);
    }
    reading.marking_B.resize(3, 0);
    EXPECT_THROW(source_marking_W(reading, source), std::logic_error);
  }
}

// voxel_relative: PCL's leaves (and its z limits 0..3 m) are laid in base_link. The wall's points (world y within
// +-1.076, z 0.198..1.802 m) fill 6 x 5 leaves of 0.4 m in the world; with base_link 0.25 m up, z - 0.25 is
// -0.052..1.552 and the points at or above 0 fill 6 x 4.
TEST(MapStages, RelativeVoxelFilterLaysItsLeavesInBaseLink) {
  Eigen::Index centroids[2] = {0, 0};
  for (const auto frame : {mapping::ZReference::kGlobal, mapping::ZReference::kBaseLink}) {
    PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
    config.filter.type = filter::FilterType::kVoxel;
    config.filter.voxel.voxel_size_m = 0.4;
    config.filter.passthrough_enabled = true;
    config.filter.passthrough = {0.0, 3.0};
    config.filter.band_before_decimation = true;
    config.cameras.front().sources.front().params.z_reference = frame;
    MapStages stages(config);
    FrameResult f = wall_frame(config, 2.0, 0.0);
    f.T_world_base = Eigen::Translation3d(0.0, 0.0, 0.25) * Eigen::Isometry3d::Identity();
    stages.sense(f);
    centroids[frame == mapping::ZReference::kBaseLink] = f.decimated_W.cols();
  }
  EXPECT_EQ(centroids[0], 6 * 5);
  EXPECT_EQ(centroids[1], 6 * 4);
}

// Banded marking sources must share one z_reference_frame: the bench filters each cloud once.
TEST(MapStages, MarkingSourcesWithDifferentBandFramesAreRefused) {
  PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
  auto& sources = config.cameras.front().sources;
  sources.push_back(sources.front());
  sources.back().name = "second";
  sources.back().params.z_reference = mapping::ZReference::kBaseLink;
  EXPECT_THROW(validate_cameras(config), std::invalid_argument);
  sources.back().params.height_band = false;  // filter none: no band, no frame
  EXPECT_NO_THROW(validate_cameras(config));
  EXPECT_EQ(band_frame(config), mapping::ZReference::kGlobal);
}

}  // namespace
}  // namespace stvl::pipeline

// STVL's layer alone, fed observations of depth images made here (no simulator): what the replay of recordings
// runs too.
#include "layer/stvl_layer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <vector>

#include "mapping/footprint.hpp"
#include "pipeline/sensing.hpp"
#include "tests/support/wall_frames.hpp"

namespace stvl::layer {
namespace {

using pipeline::Frame;
using pipeline::PipelineConfig;
using test::camera_along_x;
using test::small_config;
using test::wall_frame;

const std::vector<SensorNow> kOneCamera{{camera_along_x(), std::numeric_limits<double>::infinity()}};

// The pipeline's sensing and STVL's layer of one config, fed frame by frame.
struct SensedLayer {
  explicit SensedLayer(const PipelineConfig& config) : sensing(config), layer(pipeline::layer_config(config)) {}
  // Senses f and hands its observation to the layer; report and f keep what they did.
  void take(Frame& f, const std::vector<SensorNow>& now = kOneCamera) {
    sensing.sense(f);
    layer.update(f.observation, now, report);
  }
  const mapping::VoxelMap& map() const { return layer.voxels(); }
  pipeline::Sensing sensing;
  StvlLayer layer;
  UpdateReport report;
};

TEST(StvlLayer, MarksAWallSeenInARecordedImage) {
  SensedLayer fed(small_config(mapping::ClearingMode::kFrustum));
  Frame f = wall_frame(small_config(mapping::ClearingMode::kFrustum), 2.0, 0.0);
  fed.take(f);
  EXPECT_TRUE(fed.report.map_updated());
  ASSERT_EQ(fed.report.updates.size(), 1u);
  EXPECT_EQ(fed.report.updates[0].applied_readings.size(), 1u);
  ASSERT_FALSE(fed.map().empty());
  for (const VoxelKey& key : fed.map().voxel_keys())
    EXPECT_NEAR(fed.map().center_of(key).x(), 2.0, 0.051) << key.x << " " << key.y << " " << key.z;
  EXPECT_EQ(fed.layer.source_status(0.0).size(), 1u);
  EXPECT_EQ(fed.layer.master(), nullptr);  // no map.nav2_costmap
}

// STVL's reset (ClearEntireCostmap): every voxel gone, the buffers' last-updated time restarted (a source that was
// not current is current again for expected_update_rate).
TEST(StvlLayer, ResetEmptiesTheMapAndRestartsTheSourcesClock) {
  PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
  config.cameras.front().sources.front().params.expected_update_rate_s = 0.5;
  SensedLayer fed(config);
  Frame f = wall_frame(config, 2.0, 0.0);
  fed.take(f);
  ASSERT_FALSE(fed.map().empty());
  EXPECT_TRUE(fed.layer.current(0.5));
  EXPECT_FALSE(fed.layer.current(1.0));
  fed.layer.reset(1.0);
  EXPECT_TRUE(fed.map().empty());
  EXPECT_TRUE(fed.layer.current(1.5));
  EXPECT_FALSE(fed.layer.current(1.6));
  ASSERT_EQ(fed.layer.source_status(1.6).size(), 1u);
  EXPECT_EQ(fed.layer.source_status(1.6)[0].stale.size(), 2u);  // 0.5 .. 1.0, then 1.5 .. 1.6
}

TEST(StvlLayer, RaycastClearingRemovesAWallThatMovedAway) {
  const PipelineConfig config = small_config(mapping::ClearingMode::kRaycast);
  SensedLayer fed(config);
  Frame near = wall_frame(config, 2.0, 0.0);
  fed.take(near);
  const std::size_t at_two = fed.map().size();
  Frame far = wall_frame(config, 3.0, 0.1);
  fed.take(far);
  EXPECT_GT(fed.report.cleared_keys.size(), at_two / 2);  // the rays to the wall at 3 m pass through the old one
  for (const VoxelKey& key : fed.map().voxel_keys())
    EXPECT_GT(fed.map().center_of(key).x(), 2.5) << "a voxel of the old wall was left";
}

// nav2's update_frequency 5 Hz and a 15 Hz camera: STVL updates at 0, 0.2, 0.4 s, each with the newest reading of
// each buffer (persistence 0); the frames at 1/15 and 2/15 s are never marked.
TEST(StvlLayer, UpdatesAtTheCostmapsFrequencyTakeTheNewestReading) {
  PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
  config.map.update_frequency_hz = 5.0;
  SensedLayer fed(config);
  const double walls_m[] = {2.0, 3.0, 4.0, 0.0};  // the last frame sees nothing
  std::vector<bool> updated;
  for (int k = 0; k < 4; ++k) {
    Frame f = wall_frame(config, walls_m[k], k / 15.0);
    fed.take(f);
    updated.push_back(fed.report.map_updated());
  }
  EXPECT_EQ(updated, (std::vector<bool>{true, false, false, true}));
  ASSERT_FALSE(fed.map().empty());
  for (const VoxelKey& key : fed.map().voxel_keys())
    EXPECT_LT(fed.map().center_of(key).x(), 2.5) << "a wall of a frame between updates was marked";
}

// STVL's layer updates at every tick of the costmap's clock, frames or not. A 10 Hz camera at 4 Hz: the tick at
// 0.25 s runs when the frame at 0.3 s arrives, at its own time, with the newest reading then (the frame at 0.2 s);
// a camera that stops is applied again at every tick (persistence 0 keeps its last reading).
TEST(StvlLayer, UpdatesAtEveryTickBetweenFramesAtTheTicksTime) {
  PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
  config.map.update_frequency_hz = 4.0;
  config.map.voxel_decay_s = 100.0;
  SensedLayer fed(config);
  const double walls_m[] = {2.0, 3.0, 4.0, 0.0};
  std::vector<std::vector<double>> update_times;
  for (int k = 0; k < 4; ++k) {
    Frame f = wall_frame(config, walls_m[k], k / 10.0);
    fed.take(f);
    const UpdateReport& r = fed.report;
    update_times.emplace_back();
    for (const auto& u : r.updates) update_times.back().push_back(u.time_s);
    if (k == 3) {
      ASSERT_EQ(r.updates.size(), 1u);
      ASSERT_EQ(r.updates[0].applied_readings.size(), 1u);
      EXPECT_DOUBLE_EQ(r.updates[0].applied_readings[0].reading->time_s, 0.2);
      EXPECT_EQ(r.reapplied_readings, 1u);
    }
  }
  EXPECT_EQ(update_times, (std::vector<std::vector<double>>{{0.0}, {}, {}, {0.25}}));
  std::size_t at_tick = 0;
  for (const VoxelKey& key : fed.map().voxel_keys()) {
    const double x = fed.map().center_of(key).x(), t = *fed.map().lookup(fed.map().center_of(key));
    EXPECT_FALSE(std::abs(x - 3.0) < 0.2) << "the frame at 0.1 s fell between ticks and was marked";
    if (std::abs(t - 0.25) < 1e-12) {
      ++at_tick;
      EXPECT_NEAR(x, 4.0, 0.11) << "a voxel marked at the tick not from the newest reading";
    }
  }
  EXPECT_GT(at_tick, 100u);

  // The camera stops after 0.3 s and comes back at 1.3 s: ticks 0.5, 0.75, 1.0 and 1.25 apply its last reading.
  Frame back = wall_frame(config, 2.0, 1.3);
  fed.take(back);
  std::vector<double> times;
  for (const auto& u : fed.report.updates) times.push_back(u.time_s);
  EXPECT_EQ(times, (std::vector<double>{0.5, 0.75, 1.0, 1.25}));
  EXPECT_EQ(fed.report.reapplied_readings, 4u);
}

// STVL counts every voxel of a column toward its cell; the marking band on the voxel centres is the bench's.
TEST(StvlLayer, CostmapBandIsOursAndOff) {
  PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
  config.cameras.front().sources.front().params.min_obstacle_height_m = 0.1;
  mapping::CostmapOptions stvl = costmap_options(pipeline::layer_config(config), Eigen::Isometry3d::Identity());
  EXPECT_TRUE(std::isinf(stvl.min_obstacle_height_m) && stvl.min_obstacle_height_m < 0);
  EXPECT_TRUE(std::isinf(stvl.max_obstacle_height_m) && stvl.max_obstacle_height_m > 0);
  config.map.costmap_band = mapping::CostmapBand::kMarkingBand;
  const mapping::CostmapOptions ours = costmap_options(pipeline::layer_config(config), Eigen::Isometry3d::Identity());
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
  pipeline::CameraConfig b = config.cameras.front();
  b.name = b.sources.front().name = "b";
  config.cameras.push_back(b);
  SensedLayer fed(config);
  const auto next_at = [](double a_s, double b_s) {
    return std::vector<SensorNow>{{camera_along_x(), a_s}, {camera_along_x(), b_s}};
  };
  Frame wall = wall_frame(config, 2.0, 0.0);
  fed.take(wall, next_at(1.0, 1.0));  // camera b has no frame at 0
  EXPECT_TRUE(fed.report.map_updated());
  Frame first = wall_frame(config, 0.0, 1.0);  // no returns: the frustum clears, nothing marks
  fed.take(first, next_at(2.0, 1.0));          // camera b's frame at 1 s follows
  EXPECT_EQ(fed.report.map_updated(), grouping == mapping::UpdateGrouping::kCameraFrame);
  Frame second = wall_frame(config, 0.0, 1.0);
  second.camera_index = 1;
  fed.take(second, next_at(2.0, 2.0));
  EXPECT_TRUE(fed.report.map_updated());
  std::map<VoxelKey, double> times;
  for (const VoxelKey& key : fed.map().voxel_keys()) times[key] = *fed.map().lookup(fed.map().center_of(key));
  return times;
}

// STVL's layer clears with every source's frustum in one pass (the first frustum holding a voxel accelerates it,
// once), then marks: a voxel in both cameras' frustums at one instant ages 1./6 * 6 * 1^3 = 1 s more, not twice.
TEST(StvlLayer, CamerasSharingATimeMakeOneUpdate) {
  const auto instant = times_after_shared_instant(mapping::UpdateGrouping::kInstant);
  // One update per camera frame (camera_frame grouping): the second frame at the same time accelerates it again,
  // with the age the first left (1 - (-1) = 2 s): 1./6 * 6 * 8 = 8 s more.
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

// STVL's relative filters (z_reference_frame base_link): the band's z is base_link's. The wall at 2 m spans world
// z 1 +- 0.802 m; with the robot's base 0.5 m up (on a platform) the band 0.9..1.3 m in base_link is world z
// 1.4..1.8, in the world's z it is 0.9..1.3.
TEST(StvlLayer, RelativeBandIsInBaseLinksZ) {
  for (const auto frame : {mapping::ZReference::kGlobal, mapping::ZReference::kBaseLink}) {
    PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
    auto& source = config.cameras.front().sources.front().params;
    source.min_obstacle_height_m = 0.9;
    source.max_obstacle_height_m = 1.3;
    source.z_reference = frame;
    SensedLayer fed(config);
    Frame f = wall_frame(config, 2.0, 0.0);
    f.T_world_base = Eigen::Translation3d(0.0, 0.0, 0.5) * Eigen::Isometry3d::Identity();
    fed.take(f);
    const Observation& o = *f.observation;
    const double lo = frame == mapping::ZReference::kGlobal ? 0.9 : 1.4, hi = lo + 0.4;
    ASSERT_FALSE(fed.map().empty());
    double top = -1.0, bottom = 9.0;
    for (const VoxelKey& key : fed.map().voxel_keys()) {
      top = std::max(top, fed.map().center_of(key).z());
      bottom = std::min(bottom, fed.map().center_of(key).z());
    }
    EXPECT_NEAR(bottom, lo + 0.05, 0.051) << mapping::to_string(frame);  // voxels of 0.1 m
    EXPECT_NEAR(top, hi - 0.05, 0.051) << mapping::to_string(frame);
    if (frame == mapping::ZReference::kGlobal) {
      EXPECT_EQ(o.marking_B.cols(), 0);
      continue;
    }
    // What marks went into base_link and back, each in float as tf2's doTransform does.
    ASSERT_EQ(o.marking_B.cols(), o.marking_W.cols());
    const Eigen::Matrix3f R = f.T_world_base.linear().cast<float>();
    const Eigen::Vector3f t = f.T_world_base.translation().cast<float>();
    for (Eigen::Index i = 0; i < o.marking_W.cols(); ++i)
      ASSERT_EQ(Eigen::Vector3f(R * o.marking_B.col(i) + t), Eigen::Vector3f(o.marking_W.col(i))) << i;
    // The buffer cloud of the source: the band on base_link's z, then as marked.
    Observation reading;
    reading.marking_W = o.marking_W;
    reading.marking_B = o.marking_B;
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

// clear_footprint_voxels_below (STVL has none): after marking, the voxels inside the footprint's fill at the robot's
// pose from the floor up to the height go, and the report counts them among the cleared keys. The wall at 2 m spans
// y within +-1.076 m and z 0.198..1.802 m; a round robot of radius 0.3 m standing in it at x 2 m, clearing below
// 1.2 m, removes the columns at |y| < 0.3 up to 1.2 m and keeps everything above and beside.
TEST(StvlLayer, FootprintVoxelClearingRemovesTheRobotsOwnVoxelsBelowItsHeight) {
  for (const double height_m : {0.0, 1.2}) {
    PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
    config.map.footprint_B = mapping::footprint_from_radius(0.3);
    config.map.clear_footprint_voxels_below_m = height_m;
    SensedLayer fed(config);
    Frame f = wall_frame(config, 2.0, 0.0);
    f.T_world_base = Eigen::Translation3d(2.0, 0.0, 0.0) * Eigen::Isometry3d::Identity();
    fed.take(f);
    std::size_t inside = 0, above = 0;
    for (const VoxelKey& key : fed.map().voxel_keys()) {
      const Eigen::Vector3d c = fed.map().center_of(key);
      if (std::abs(c.y()) < 0.2 && std::abs(c.x() - 2.0) < 0.2) (c.z() < 1.2 ? inside : above) += 1;
    }
    EXPECT_GT(above, 0u);
    if (height_m == 0.0) {
      EXPECT_EQ(fed.report.footprint_voxels_cleared, 0u);
      EXPECT_GT(inside, 0u);  // the wall's own voxels stand in the footprint
      continue;
    }
    EXPECT_EQ(inside, 0u);
    EXPECT_GT(fed.report.footprint_voxels_cleared, 0u);
    EXPECT_EQ(fed.report.cleared_keys.size(), fed.report.footprint_voxels_cleared);  // the frustum removed none
  }
}

}  // namespace
}  // namespace stvl::layer

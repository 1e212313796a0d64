// nav2's VoxelLayer and ObstacleLayer as layers (Nav2Layer), fed hand-made observations: a few points from a camera
// whose cells, rays and ranges are worked out by hand in each test's comment (cell = floor((x - origin) / 0.1)).
#include "layer/nav2_layer.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "mapping/footprint.hpp"

namespace stvl::layer {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A fixed 4 m x 4 m window at the origin, 0.1 m cells (40 x 40), one camera whose source marks and clears, nav2's
// defaults otherwise; the voxel layer's levels 0.1 m from z = 0 (z_voxels 10).
LayerConfig config_of(LayerType type) {
  LayerConfig c;
  c.type = type;
  c.map.voxel_size_m = 0.1;
  c.nav2_costmap.width_m = 4.0;
  c.nav2_costmap.height_m = 4.0;
  c.nav2_costmap.resolution_m = 0.1;
  c.nav2_costmap.rolling_window = false;
  c.nav2.z_resolution_m = 0.1;
  c.nav2.z_voxels = 10;
  SensorConfig sensor;
  sensor.rate_hz = 10.0;
  SourceConfig source;
  source.params.marking = source.params.clearing = true;
  source.params.min_obstacle_height_m = 0.0;
  source.params.max_obstacle_height_m = 2.0;
  sensor.sources = {source};
  c.sensors = {sensor};
  return c;
}

// An observation at time_s from a camera at camera_W (the robot under it), with these points (world frame).
std::shared_ptr<Observation> observation(double time_s, const Eigen::Vector3d& camera_W,
                                         const std::vector<Eigen::Vector3f>& points_W) {
  auto o = std::make_shared<Observation>();
  o->time_s = time_s;
  o->T_world_camera = Eigen::Translation3d(camera_W) * Eigen::Isometry3d::Identity();
  o->T_world_base = Eigen::Translation3d(camera_W.x(), camera_W.y(), 0.0) * Eigen::Isometry3d::Identity();
  o->decimated_W.resize(3, static_cast<Eigen::Index>(points_W.size()));
  for (std::size_t i = 0; i < points_W.size(); ++i) o->decimated_W.col(static_cast<Eigen::Index>(i)) = points_W[i];
  o->marking_W = o->decimated_W;
  return o;
}

const std::vector<SensorNow> kOneCamera{{Eigen::Isometry3d::Identity(), kInf}};

std::uint8_t cell(const Nav2Layer& layer, unsigned x, unsigned y) { return layer.layer_grid().cost(x, y); }

// Camera at (0.55, 2.05, 0.55) = cell (5.5, 20.5, 5.5); a point at (2.05, 2.05, 0.55) = voxel (20, 20, 5), 1.5 m
// away. The ray stops 2 cells (0.2 m) short: its end (1.85, 2.05, 0.55) = cell 18.5, so the walk frees x = 5..18 of
// row 20 at level 5 (13 steps, 14 cells); cell 19 keeps its default, cell 20 is marked and lethal.
TEST(Nav2Layer, VoxelLayerMarksThePointAndClearsTheRayTwoCellsShort) {
  LayerConfig c = config_of(LayerType::kNav2Voxel);
  c.nav2_costmap.track_unknown_space = true;  // the default cell is 255, so the cleared ones show
  Nav2Layer layer(c);
  UpdateReport report;
  layer.update(observation(0.0, {0.55, 2.05, 0.55}, {{2.05f, 2.05f, 0.55f}}), kOneCamera, report);
  ASSERT_EQ(report.updates.size(), 1u);
  EXPECT_EQ(layer.voxel_grid().voxel(20, 20, 5), nav2::VoxelStatus::kMarked);
  EXPECT_EQ(cell(layer, 20, 20), nav2::kLethalObstacle);
  EXPECT_EQ(cell(layer, 19, 20), nav2::kNoInformation);
  for (unsigned x = 5; x <= 18; ++x) {
    EXPECT_EQ(cell(layer, x, 20), nav2::kFreeSpace) << x;
    EXPECT_EQ(layer.voxel_grid().voxel(x, 20, 5), nav2::VoxelStatus::kFree) << x;
  }
  EXPECT_EQ(cell(layer, 4, 20), nav2::kNoInformation);
  // The bench's view: the one voxel, at the same key (0.1 m cubes on the same lines).
  ASSERT_EQ(layer.voxels().size(), 1u);
  EXPECT_EQ(layer.voxels().voxel_keys().front(), (VoxelKey{20, 20, 5}));
  // The master took the layer's cells inside the bounds touched: the ray's end (1.85) and the point (2.05) only, as
  // VoxelLayer::raytraceFreespace touches no origin (ObstacleLayer's does): cells 18..20 of row 20, not cell 10.
  EXPECT_EQ(layer.master()->master().at(20, 20), mapping::kCostLethal);
  EXPECT_EQ(layer.master()->master().at(18, 20), mapping::kCostFree);
  EXPECT_EQ(layer.master()->master().at(10, 20), mapping::kCostUnknown);
}

// unknown_threshold 0 (VoxelLayer adds 16 - z_voxels = 6): a cleared column still holds 15 unknown levels (9 of its
// 10 plus the 6 above), more than 6, so its cell becomes NO_INFORMATION, not free.
TEST(Nav2Layer, VoxelLayerLeavesAColumnUnknownAboveTheUnknownThreshold) {
  LayerConfig c = config_of(LayerType::kNav2Voxel);
  c.nav2.unknown_threshold = 0;
  Nav2Layer layer(c);  // track_unknown_space false: the default cell is free, the cleared ones are not
  UpdateReport report;
  layer.update(observation(0.0, {0.55, 2.05, 0.55}, {{2.05f, 2.05f, 0.55f}}), kOneCamera, report);
  EXPECT_EQ(cell(layer, 10, 20), nav2::kNoInformation);
  EXPECT_EQ(cell(layer, 19, 20), nav2::kFreeSpace);  // never walked: the default
  EXPECT_EQ(cell(layer, 20, 20), nav2::kLethalObstacle);
}

// A low box at (1.05, 2.05, 0.15) seen first, then a wall at (2.05, 2.05, 0.55) behind it. The wall's ray passes
// over the box: in 3D at level 5, far above the box's level 1, so the voxel layer keeps the box; in 2D it walks the
// box's cell (10, 20), so the obstacle layer frees it (the 2D layer's known blind spot with 3D clouds).
TEST(Nav2Layer, ARayOverALowBoxFreesItsCellIn2dOnly) {
  for (const LayerType type : {LayerType::kNav2Voxel, LayerType::kNav2Obstacle}) {
    Nav2Layer layer(config_of(type));
    UpdateReport report;
    layer.update(observation(0.0, {0.55, 2.05, 0.55}, {{1.05f, 2.05f, 0.15f}}), kOneCamera, report);
    ASSERT_EQ(cell(layer, 10, 20), nav2::kLethalObstacle) << to_string(type);
    layer.update(observation(0.1, {0.55, 2.05, 0.55}, {{2.05f, 2.05f, 0.55f}}), kOneCamera, report);
    EXPECT_EQ(cell(layer, 20, 20), nav2::kLethalObstacle) << to_string(type);
    EXPECT_EQ(cell(layer, 10, 20), type == LayerType::kNav2Voxel ? nav2::kLethalObstacle : nav2::kFreeSpace)
        << to_string(type);
  }
}

// The voxel layer marks with the 3D squared distance from the origin: a point at 2.6 m (>= obstacle_max_range 2.5)
// is not marked but its ray (raytrace_max_range 3.0 m = 30 cells) clears; one at 2.4 m is marked.
TEST(Nav2Layer, VoxelLayerMarksOnlyInsideObstacleMaxRange) {
  Nav2Layer layer(config_of(LayerType::kNav2Voxel));
  UpdateReport report;
  layer.update(observation(0.0, {0.55, 1.05, 0.55}, {{3.15f, 1.05f, 0.55f}, {2.95f, 3.05f, 0.55f}}), kOneCamera,
               report);
  EXPECT_EQ(layer.voxel_grid().voxel(31, 10, 5), nav2::VoxelStatus::kUnknown);  // 2.6 m: not marked
  EXPECT_EQ(layer.voxel_grid().voxel(28, 10, 5), nav2::VoxelStatus::kFree);     // its ray, 0.2 m short
  // (2.95, 3.05): dx 2.4, dy 2.0: 3.12 m, too far as well; a nearer one:
  layer.update(observation(0.1, {0.55, 1.05, 0.55}, {{2.95f, 1.05f, 0.55f}}), kOneCamera, report);
  EXPECT_EQ(layer.voxel_grid().voxel(29, 10, 5), nav2::VoxelStatus::kMarked);  // 2.4 m
  EXPECT_EQ(layer.voxel_grid().voxel(31, 10, 5), nav2::VoxelStatus::kUnknown);
}

// A rolling 2 m window (20 x 20 cells): getSizeInMetersX = 19.5 cells, so at the robot (1.0, 1.0) the origin is
// 1.0 - 0.975 = 0.025, truncated to whole cells from (0, 0): 0.0. The robot moves to (1.5, 1.0): the origin to
// int(0.525 / 0.1) = 5 cells = 0.5 m; a voxel marked at world (1.75, 1.05) moves from cell 17 to cell 12, and the
// cells that entered on the right are unknown columns.
TEST(Nav2Layer, RollingWindowKeepsVoxelsWhereTheyAreInTheWorld) {
  LayerConfig c = config_of(LayerType::kNav2Voxel);
  c.nav2_costmap.width_m = c.nav2_costmap.height_m = 2.0;
  c.nav2_costmap.rolling_window = true;
  Nav2Layer layer(c);
  UpdateReport report;
  layer.update(observation(0.0, {1.0, 1.05, 0.55}, {{1.75f, 1.05f, 0.55f}}), kOneCamera, report);
  EXPECT_DOUBLE_EQ(layer.layer_grid().origin_x_m, 0.0);
  EXPECT_EQ(layer.voxel_grid().voxel(17, 10, 5), nav2::VoxelStatus::kMarked);
  layer.update(observation(0.1, {1.5, 1.05, 0.55}, {}), kOneCamera, report);
  EXPECT_NEAR(layer.layer_grid().origin_x_m, 0.5, 1e-12);
  EXPECT_EQ(layer.voxel_grid().voxel(12, 10, 5), nav2::VoxelStatus::kMarked);
  EXPECT_EQ(layer.voxel_grid().column(19, 10), nav2::kUnknownColumn);
  EXPECT_EQ(layer.voxels().voxel_keys(), (std::vector<VoxelKey>{{17, 10, 5}}));  // the same voxel in the world
  EXPECT_NEAR(layer.master()->master().origin_m.x(), 0.5, 1e-12);
}

// footprint_clearing_enabled: the footprint's cells are freed in the layer's grid after marking (updateCosts), the
// voxel under it stays in the voxel grid.
TEST(Nav2Layer, FootprintClearingFreesTheCellsNotTheVoxels) {
  LayerConfig c = config_of(LayerType::kNav2Voxel);
  c.map.footprint_B = mapping::footprint_from_radius(0.3);
  Nav2Layer layer(c);
  UpdateReport report;
  // Camera over the robot at (2.05, 2.05); a point 0.1 m ahead, under the footprint, and one at 1 m ahead.
  layer.update(observation(0.0, {2.05, 2.05, 0.55}, {{2.15f, 2.05f, 0.15f}, {3.05f, 2.05f, 0.15f}}), kOneCamera,
               report);
  EXPECT_EQ(layer.voxel_grid().voxel(21, 20, 1), nav2::VoxelStatus::kMarked);
  EXPECT_EQ(cell(layer, 21, 20), nav2::kFreeSpace);
  EXPECT_EQ(cell(layer, 30, 20), nav2::kLethalObstacle);
  c.nav2.footprint_clearing_enabled = false;
  Nav2Layer kept(c);
  kept.update(observation(0.0, {2.05, 2.05, 0.55}, {{2.15f, 2.05f, 0.15f}}), kOneCamera, report);
  EXPECT_EQ(cell(kept, 21, 20), nav2::kLethalObstacle);
}

// update_frequency 5 Hz and a 15 Hz camera: cycles at 0 and 0.2 s only; the frames at 1/15 and 2/15 s only go into
// the buffer (persistence 0 keeps the newest: the cycle at 0.2 s takes the frame at 0.2 s).
TEST(Nav2Layer, CyclesRunAtTheCostmapsFrequency) {
  LayerConfig c = config_of(LayerType::kNav2Obstacle);
  c.map.update_frequency_hz = 5.0;
  Nav2Layer layer(c);
  UpdateReport report;
  std::vector<std::size_t> cycles;
  const float xs[] = {1.05f, 1.55f, 2.05f, 2.55f};
  for (int k = 0; k < 4; ++k) {
    layer.update(observation(k / 15.0, {0.55, 2.05, 0.55}, {{xs[k], 2.05f, 0.55f}}), kOneCamera, report);
    cycles.push_back(report.updates.size());
  }
  EXPECT_EQ(cycles, (std::vector<std::size_t>{1, 0, 0, 1}));
  EXPECT_EQ(cell(layer, 10, 20), nav2::kFreeSpace);  // marked at 0 s, then on the ray to 2.55 at 0.2 s
  EXPECT_EQ(cell(layer, 15, 20), nav2::kFreeSpace);  // never applied
  EXPECT_EQ(cell(layer, 25, 20), nav2::kLethalObstacle);
  EXPECT_EQ(layer.cycles(), 2u);
}

// isCurrent (ObservationBuffer::isCurrent): within expected_update_rate of the last reception; reset() restarts
// that clock (resetBuffersLastUpdated) without dropping the readings.
TEST(Nav2Layer, CurrentWithinTheExpectedRateAndAgainAfterAReset) {
  LayerConfig c = config_of(LayerType::kNav2Voxel);
  c.sensors[0].sources[0].params.expected_update_rate_s = 0.3;
  Nav2Layer layer(c);
  UpdateReport report;
  layer.update(observation(1.0, {0.55, 2.05, 0.55}, {{2.05f, 2.05f, 0.55f}}), kOneCamera, report);
  EXPECT_TRUE(layer.current(1.3));
  EXPECT_FALSE(layer.current(1.31));
  layer.reset(2.0);
  EXPECT_TRUE(layer.current(2.3));
  EXPECT_FALSE(layer.current(2.31));
  EXPECT_EQ(cell(layer, 20, 20), nav2::kFreeSpace) << "the reset empties the grid (track_unknown_space false)";
  // A source stale from 0.3 s (created at 0) to its first reading, from 1.3 s until the reset, then from 2.3 s until
  // its next reading at 2.5 s.
  layer.update(observation(2.5, {0.55, 2.05, 0.55}, {{2.05f, 2.05f, 0.55f}}), kOneCamera, report);
  const std::vector<SourceStatus> status = layer.source_status(2.5);
  ASSERT_EQ(status.size(), 1u);
  ASSERT_EQ(status[0].stale.size(), 3u);
  EXPECT_NEAR(status[0].stale[1].from_s, 1.3, 1e-9);
  EXPECT_NEAR(status[0].stale[1].to_s, 2.0, 1e-9);
  EXPECT_NEAR(status[0].stale[2].from_s, 2.3, 1e-9);
  EXPECT_NEAR(status[0].stale[2].to_s, 2.5, 1e-9);
}

// purgeStaleObservations ages a reading from its header stamp: a reading delivered 0.3 s after its stamp with
// observation_persistence 0.2 is purged on arrival, the newest included, and marks nothing.
TEST(Nav2Layer, PersistenceAgesAReadingFromItsHeaderStamp) {
  for (const double latency_s : {0.1, 0.3}) {
    LayerConfig c = config_of(LayerType::kNav2Voxel);
    c.sensors[0].sources[0].params.observation_persistence_s = 0.2;
    Nav2Layer layer(c);
    UpdateReport report;
    const auto o = observation(1.0 + latency_s, {0.55, 2.05, 0.55}, {{2.05f, 2.05f, 0.55f}});
    o->stamp_s = 1.0;
    layer.update(o, kOneCamera, report);
    EXPECT_EQ(cell(layer, 20, 20), latency_s < 0.2 ? nav2::kLethalObstacle : nav2::kFreeSpace)
        << "latency " << latency_s;
  }
}

// The obstacle layer's range rules (nav2_obstacle_layer.hpp): a point at 2.5 m plus a hair (2D) is past
// obstacle_max_range in metres, but its cell, 25 cells from the origin's, is not past cellDistance(2.5) = 25: #5697
// marks it, #6092's 2D prefilter and the 3D rule before #5697 do not.
TEST(Nav2Layer, ObstacleLayerMarksByTheChosenRangeRule) {
  const std::pair<nav2::MarkingRange, bool> rules[] = {{nav2::MarkingRange::kWorld3d, false},
                                                       {nav2::MarkingRange::kCells, true},
                                                       {nav2::MarkingRange::kCellsAndWorld2d, false}};
  for (const auto& [rule, marked] : rules) {
    LayerConfig c = config_of(LayerType::kNav2Obstacle);
    c.nav2.marking_range = rule;
    c.sensors[0].sources[0].params.clearing = false;
    Nav2Layer layer(c);
    UpdateReport report;
    layer.update(observation(0.0, {0.55, 2.05, 0.55}, {{3.0501f, 2.05f, 0.55f}}), kOneCamera, report);
    EXPECT_EQ(cell(layer, 30, 20) == nav2::kLethalObstacle, marked) << to_string(rule);
  }
}

TEST(Nav2Layer, RejectsABadConfigNamingTheKey) {
  const auto message = [](const LayerConfig& c) {
    try {
      Nav2Layer layer(c);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  LayerConfig c = config_of(LayerType::kNav2Voxel);
  c.nav2.z_voxels = 17;
  EXPECT_NE(message(c).find("z_voxels"), std::string::npos) << message(c);
  c = config_of(LayerType::kNav2Voxel);
  c.sensors[0].sources[0].nav2.raytrace_max_range_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(message(c).find("raytrace_max_range"), std::string::npos) << message(c);
  c = config_of(LayerType::kNav2Obstacle);
  c.sensors[0].sources[0].nav2.obstacle_min_range_m = -1.0;
  EXPECT_NE(message(c).find("obstacle_min_range"), std::string::npos) << message(c);
  c = config_of(LayerType::kNav2Voxel);
  c.nav2_costmap.resolution_m = 0.05;
  EXPECT_NE(message(c).find("resolution"), std::string::npos) << message(c);
  c = config_of(LayerType::kNav2Voxel);
  c.nav2.combination_method = 3;
  EXPECT_NE(message(c).find("combination_method"), std::string::npos) << message(c);
}

// Without map.nav2_costmap a nav2 layer runs in a rolling window holding its farthest range: 2 * 3.0 + 1 = 7 m.
TEST(Nav2Layer, DefaultWindowHoldsTheSourcesReach) {
  LayerConfig c = config_of(LayerType::kNav2Obstacle);
  c.nav2_costmap = {};
  Nav2Layer layer(c);
  EXPECT_TRUE(layer.master()->config().rolling_window);
  EXPECT_EQ(layer.layer_grid().size_x_cells, 70u);
  EXPECT_FALSE(layer.has_voxels());
  EXPECT_TRUE(layer.voxels().empty());
}

}  // namespace
}  // namespace stvl::layer

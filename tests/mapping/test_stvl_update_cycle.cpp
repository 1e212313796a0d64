// STVL's update cycle as the map keeps it (layer.cpp updateBounds, grid.cpp ClearFrustums /
// TemporalClearAndGenerateCostmap, ros2 403d9ed and noetic-devel 5e06daf): the costmap is built while clearing,
// before the marks, so an update's new voxels reach it one update later (CostmapTiming::kStvl); decay and the
// frustum's acceleration on hand-computed numbers. Each test fails with the bench's old arithmetic.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "mapping/voxel_map.hpp"
#include "test_helpers.hpp"

namespace stvl::mapping {
namespace {

using test::camera_looking_along_x;
using test::cloud;
using test::wide_source;

StvlConfig timing_config(CostmapTiming timing) {
  StvlConfig config = test::exact_config();
  config.costmap_timing = timing;
  config.voxel_decay_s = 10.0;
  return config;
}

// Lethal cells of the projection over a fixed 1 x 1 m window at the origin (0.125 m cells).
int lethal_cells(const VoxelMap& map) {
  CostmapOptions options;
  options.bounds_W = Eigen::AlignedBox2d(Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 1));
  int lethal = 0;
  for (const auto cell : map.project_costmap(options).cells) lethal += cell == kCostLethal;
  return lethal;
}

TEST(StvlCostmapTiming, NewVoxelsReachTheCostmapOneUpdateLater) {
  const auto camera_W = camera_looking_along_x({-5, 0.5, 0.5});
  for (const CostmapTiming timing : {CostmapTiming::kStvl, CostmapTiming::kAfterMark}) {
    VoxelMap map(timing_config(timing));
    // Update 1: clear (nothing there), then mark two points in two columns.
    map.clear({}, 1.0);
    map.mark(cloud({{0.3f, 0.3f, 0.3f}, {0.6f, 0.6f, 0.3f}}), camera_W, wide_source(), 1.0);
    EXPECT_EQ(map.size(), 2u);
    // STVL's layer publishes the costmap it built before marking: nothing yet. Ours: both columns.
    EXPECT_EQ(lethal_cells(map), timing == CostmapTiming::kStvl ? 0 : 2) << to_string(timing);
    // Update 2: the clear rebuilds the costmap from the voxels there are; a third point is marked.
    map.clear({}, 2.0);
    map.mark(cloud({{0.3f, 0.3f, 0.3f}, {0.9f, 0.1f, 0.3f}}), camera_W, wide_source(), 2.0);
    // The refreshed voxel (0.3, 0.3) existed before the mark and counts; the new (0.9, 0.1) waits a turn.
    EXPECT_EQ(lethal_cells(map), timing == CostmapTiming::kStvl ? 2 : 3) << to_string(timing);
    map.clear({}, 3.0);
    EXPECT_EQ(lethal_cells(map), 3) << to_string(timing);
  }
}

TEST(StvlCostmapTiming, AVoxelClearedAtItsFirstPassNeverReachesTheCostmap) {
  // STVL's consequence of the lag: with voxel_decay < its update period a voxel is gone before any costmap
  // counts it. Here decay 0.5 s and updates 1 s apart.
  StvlConfig config = timing_config(CostmapTiming::kStvl);
  config.voxel_decay_s = 0.5;
  config.clearing_walk = ClearingWalk::kFullWalk;
  VoxelMap map(config);
  const auto camera_W = camera_looking_along_x({-5, 0.5, 0.5});
  map.clear({}, 1.0);
  map.mark(cloud({{0.3f, 0.3f, 0.3f}}), camera_W, wide_source(), 1.0);
  EXPECT_EQ(lethal_cells(map), 0);
  map.clear({}, 2.0);  // age 1 s > 0.5 s: removed while the costmap is built
  EXPECT_EQ(map.size(), 0u);
  EXPECT_EQ(lethal_cells(map), 0);
}

TEST(StvlCostmapTiming, NamesParse) {
  EXPECT_EQ(parse_costmap_timing("stvl"), CostmapTiming::kStvl);
  EXPECT_EQ(parse_costmap_timing("after_mark"), CostmapTiming::kAfterMark);
  EXPECT_EQ(to_string(CostmapTiming::kAfterMark), "after_mark");
  EXPECT_THROW(parse_costmap_timing("before_mark"), std::invalid_argument);
  EXPECT_EQ(StvlConfig{}.costmap_timing, CostmapTiming::kStvl);  // STVL's is the default
}

// GetTemporalClearingDuration and GetFrustumAcceleration on numbers worked by hand: a voxel marked at t = 0,
// cleared at t = 2 s inside a frustum with decay_acceleration 3 /s^3: acceleration 1/6 * 3 * 2^3 = 4 s.
struct DecayCase {
  DecayModel model;
  double voxel_decay_s;
  bool survives;         // time left (base - 4 s) >= 0
  double value_after_s;  // the stored time pulled back by 4 s when it survives
};

TEST(StvlDecay, EachModelWithTheFrustumAcceleration) {
  // linear: base = 10 - 2 = 8 >= 4: kept, value 0 - 4. exponential: 10 e^-2 = 1.353 < 4: removed.
  // persistent: base = 10 >= 4: kept. linear with decay 5.5: 3.5 < 4: removed (plain decay would keep it).
  const DecayCase cases[] = {{DecayModel::kLinear, 10.0, true, -4.0},
                             {DecayModel::kExponential, 10.0, false, 0.0},
                             {DecayModel::kPersistent, 10.0, true, -4.0},
                             {DecayModel::kLinear, 5.5, false, 0.0},
                             {DecayModel::kExponential, 40.0, true, -4.0}};  // 40 e^-2 = 5.41 >= 4
  for (const DecayCase& c : cases) {
    for (const ClearingWalk walk : {ClearingWalk::kFullWalk, ClearingWalk::kBounded}) {
      StvlConfig config = test::exact_config();
      config.decay_model = c.model;
      config.voxel_decay_s = c.voxel_decay_s;
      config.clearing_walk = walk;
      VoxelMap map(config);
      ObservationSource source = wide_source();
      source.decay_acceleration_per_s3 = 3.0;
      const auto camera_W = camera_looking_along_x({0, 0.0625, 0.0625});
      map.mark(cloud({{2.0625f, 0.0625f, 0.0625f}}), camera_W, source, 0.0);
      map.clear({{camera_W, source}}, 2.0);
      const auto value = map.lookup({2.0625, 0.0625, 0.0625});
      ASSERT_EQ(value.has_value(), c.survives) << to_string(c.model) << " decay " << c.voxel_decay_s;
      if (value) EXPECT_DOUBLE_EQ(*value, c.value_after_s);
      // Outside every frustum only the plain decay counts, and every case keeps it (linear 5.5: 3.5 s left).
      VoxelMap outside(config);
      outside.mark(cloud({{2.0625f, 0.0625f, 0.0625f}}), camera_W, source, 0.0);
      outside.clear({}, 2.0);
      EXPECT_TRUE(outside.lookup({2.0625, 0.0625, 0.0625}).has_value()) << to_string(c.model);
    }
  }
}

TEST(StvlDecay, LinearExpiryIsStrict) {
  // STVL removes when time left < 0: a linear voxel with decay 2 s is kept at age exactly 2 s, gone after.
  StvlConfig config = test::exact_config();
  config.voxel_decay_s = 2.0;
  for (const ClearingWalk walk : {ClearingWalk::kFullWalk, ClearingWalk::kBounded}) {
    config.clearing_walk = walk;
    VoxelMap map(config);
    map.mark(cloud({{1.0625f, 0.0625f, 0.0625f}}), camera_looking_along_x({0, 0, 0}), wide_source(), 0.0);
    map.clear({}, 2.0);
    EXPECT_EQ(map.size(), 1u) << to_string(walk);
    map.clear({}, 2.0 + 1e-9);
    EXPECT_EQ(map.size(), 0u) << to_string(walk);
  }
}

}  // namespace
}  // namespace stvl::mapping

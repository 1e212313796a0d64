// nav2's two costmaps around the layer (navigation/costmaps.hpp): the rolling window, updateWithMax, the static map,
// clearing and the update clock.
#include <gtest/gtest.h>

#include "navigation/costmaps.hpp"

namespace stvl::navigation {
namespace {

mapping::Costmap2D grid(int w, int h, double res, Eigen::Vector2d origin, std::uint8_t fill = mapping::kCostFree) {
  mapping::Costmap2D m;
  m.width = w, m.height = h, m.resolution_m = res, m.origin_m = origin;
  m.cells.assign(static_cast<std::size_t>(w) * h, fill);
  return m;
}

std::uint8_t at(const mapping::Costmap2D& m, double x, double y) {
  const int cx = static_cast<int>((x - m.origin_m.x()) / m.resolution_m);
  const int cy = static_cast<int>((y - m.origin_m.y()) / m.resolution_m);
  return m.cells[static_cast<std::size_t>(cy) * m.width + cx];
}

TEST(Costmaps, RollingWindowFollowsTheRobotByWholeCells) {
  CostmapParams p;  // 3 x 3 m at 0.05, 5 Hz
  NavCostmap local(p, 0.2);
  EXPECT_EQ(local.costmap().width, 60);
  const mapping::Costmap2D layer = grid(1, 1, 0.05, {100, 100});
  local.update(0.0, layer, {1.02, 0.0});
  // new origin = robot - 1.5 m, moved from (0, 0) by whole cells, truncated toward zero as updateOrigin's int cast:
  // (1.02 - 1.5) / 0.05 = -9.6 -> -9 cells.
  EXPECT_NEAR(local.costmap().origin_m.x(), -9 * 0.05, 1e-9);
  EXPECT_NEAR(local.costmap().origin_m.y(), -1.5, 1e-9);
}

TEST(Costmaps, LayerCombinedWithMaxAndItsUnknownSkipped) {
  CostmapParams p;
  p.track_unknown_space = true;
  NavCostmap local(p, 0.2);
  mapping::Costmap2D layer = grid(40, 40, 0.05, {-1, -1}, mapping::kCostUnknown);
  layer.cells[20 * 40 + 30] = mapping::kCostLethal;  // (0.5 .. 0.55, 0 .. 0.05)
  layer.cells[20 * 40 + 10] = mapping::kCostFree;    // (-0.5, 0)
  local.update(0.0, layer, {0, 0});
  EXPECT_EQ(at(local.combined(), 0.52, 0.02), mapping::kCostLethal);
  EXPECT_EQ(at(local.combined(), -0.48, 0.02), mapping::kCostFree);  // unknown master takes the layer's free
  EXPECT_EQ(at(local.combined(), 0.0, 0.9), mapping::kCostUnknown);  // the layer's unknown skipped
  EXPECT_EQ(at(local.combined(), 1.3, 1.3), mapping::kCostUnknown);  // outside the layer's grid
  // Inflation around the lethal cell: the next cell is within the inscribed radius.
  EXPECT_EQ(at(local.costmap(), 0.47, 0.02), 253);
}

TEST(Costmaps, GlobalKeepsTheStaticMapUnderTheLayerAndAfterAClear) {
  CostmapParams p{0, 0, 0.1, 1.0, 1.0, false, true, {}};
  mapping::Costmap2D building = grid(50, 30, 0.1, {0, 0});
  for (int y = 0; y < 30; ++y) building.cells[static_cast<std::size_t>(y) * 50 + 25] = mapping::kCostLethal;
  NavCostmap global(p, 0.2, building);
  mapping::Costmap2D layer = grid(50, 30, 0.1, {0, 0});
  layer.cells[10 * 50 + 5] = mapping::kCostLethal;
  global.update(0.0, layer, {1, 1});
  EXPECT_EQ(at(global.combined(), 2.55, 1.05), mapping::kCostLethal);  // the wall: free in the layer, kept
  EXPECT_EQ(at(global.combined(), 0.55, 1.05), mapping::kCostLethal);  // the layer's obstacle
  global.clear();
  EXPECT_EQ(at(global.combined(), 0.55, 1.05), mapping::kCostFree);
  EXPECT_EQ(at(global.combined(), 2.55, 1.05), mapping::kCostLethal);
}

TEST(Costmaps, UpdateClock) {
  CostmapParams p;  // 5 Hz
  NavCostmap local(p, 0.2);
  EXPECT_TRUE(local.due(0.0));
  local.update(0.0, grid(1, 1, 0.05, {0, 0}), {0, 0});
  EXPECT_FALSE(local.due(0.15));
  EXPECT_TRUE(local.due(0.2));
}

TEST(Costmaps, RefuseAStaticMapOfAnotherResolutionOrNoCells) {
  CostmapParams p{0, 0, 0.05, 1.0, 1.0, false, true, {}};
  EXPECT_THROW(NavCostmap(p, 0.2, grid(10, 10, 0.1, {0, 0})), std::invalid_argument);
  CostmapParams tiny;
  tiny.width_m = 0.01;
  EXPECT_THROW(NavCostmap(tiny, 0.2), std::invalid_argument);
}

TEST(Costmaps, StaticLayerReadsANav2MapAsNav2sInterpretValue) {
  // A 4 x 2 map at 0.1 m from (-1, -2): 100 lethal, -1 unknown, the rest (0, and 50 or 99 in a scale-mode map)
  // free under trinary_costmap; an out-of-range byte (-2, 254 unsigned) is >= the lethal threshold as in nav2.
  OccupancyMap map{4, 2, 0.1, {-1.0, -2.0}, {0, 100, -1, 50, 99, -2, 0, 100}};
  const mapping::Costmap2D tracked = static_layer_costmap(map, /*track_unknown_space=*/true);
  EXPECT_EQ(tracked.width, 4);
  EXPECT_EQ(tracked.height, 2);
  EXPECT_DOUBLE_EQ(tracked.resolution_m, 0.1);
  EXPECT_EQ(tracked.origin_m, Eigen::Vector2d(-1.0, -2.0));
  const std::vector<std::uint8_t> expected{0, 254, 255, 0, 0, 254, 0, 254};
  EXPECT_EQ(tracked.cells, expected);
  const mapping::Costmap2D untracked = static_layer_costmap(map, false);
  EXPECT_EQ(untracked.cells[2], mapping::kCostFree);  // unknown is free without track_unknown_space
  map.data.pop_back();
  EXPECT_THROW(static_layer_costmap(map, true), std::invalid_argument);
}

}  // namespace
}  // namespace stvl::navigation

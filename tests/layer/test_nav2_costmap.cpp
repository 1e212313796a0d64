// nav2's master costmap with STVL as its layer (layer/nav2_costmap.hpp) on hand-made layers: the master resets
// only inside the bounds STVL touches, so a cell STVL stops marking stays lethal unless its cleared voxel touches
// it (STVL #199, fixed by #200/#203); the rolling window keeps what overlaps and starts new cells at the default.
#include "layer/nav2_costmap.hpp"

#include <gtest/gtest.h>

namespace stvl::layer {
namespace {

using mapping::Costmap2D;
using mapping::kCostFree;
using mapping::kCostLethal;
using mapping::kCostUnknown;

Nav2CostmapConfig small(bool touch_cleared) {
  Nav2CostmapConfig c;
  c.width_m = 1.0;  // 10 x 10 cells of 0.1 m
  c.height_m = 1.0;
  c.resolution_m = 0.1;
  c.rolling_window = false;
  c.touch_cleared_cells = touch_cleared;
  return c;
}

void set(Costmap2D& m, int x, int y, std::uint8_t v) { m.cells[static_cast<std::size_t>(y) * m.width + x] = v; }
std::uint8_t get(const Costmap2D& m, int x, int y) { return m.at(x, y); }

TEST(Nav2Costmap, AnObstacleThatLeavesStaysLethalUnlessItsCellIsTouched) {
  for (const bool touch : {false, true}) {
    Nav2Costmap nav2(small(touch));
    Costmap2D layer = nav2.window_at({0.5, 0.5});
    set(layer, 2, 3, kCostLethal);
    nav2.update(layer, {}, {});
    EXPECT_EQ(get(nav2.master(), 2, 3), kCostLethal);
    // The voxel at (0.25, 0.35) m decays: STVL's layer is empty and its cleared cell is all it touches.
    layer = nav2.window_at({0.5, 0.5});
    nav2.update(layer, {{0.25, 0.35}}, {});
    EXPECT_EQ(get(nav2.master(), 2, 3), touch ? kCostFree : kCostLethal) << touch;
    EXPECT_EQ(nav2.ghost_cells(layer), touch ? 0u : 1u);
    // The run's record of ghosts: one update without, then this one.
    nav2.count_ghosts(0.5, layer);
    nav2.count_ghosts(1.0, layer);
    EXPECT_EQ(nav2.ghosts().updates, 2u);
    EXPECT_EQ(nav2.ghosts().updates_with_ghosts, touch ? 0u : 2u);
    EXPECT_EQ(nav2.ghosts().max_cells, touch ? 0u : 1u);
    EXPECT_EQ(nav2.ghosts().max_at_s, touch ? 0.0 : 0.5);  // the first update with the most
    EXPECT_EQ(nav2.ghosts().last_cells, touch ? 0u : 1u);
  }
}

TEST(Nav2Costmap, ResetOnlyInsideTheBoundingBoxOfWhatWasTouched) {
  Nav2Costmap nav2(small(true));
  Costmap2D layer = nav2.window_at({0.5, 0.5});
  set(layer, 1, 1, kCostLethal);
  set(layer, 8, 8, kCostLethal);
  nav2.update(layer, {}, {});
  // Next cycle: only (1, 1) and (3, 2) are lethal; the box [1, 3] x [1, 2] is reset, (8, 8) is outside it.
  layer = nav2.window_at({0.5, 0.5});
  set(layer, 1, 1, kCostLethal);
  set(layer, 3, 2, kCostLethal);
  nav2.update(layer, {}, {});
  EXPECT_EQ(get(nav2.master(), 3, 2), kCostLethal);
  EXPECT_EQ(get(nav2.master(), 8, 8), kCostLethal);  // a ghost: nothing touched it
  EXPECT_EQ(nav2.ghost_cells(layer), 1u);
  // The footprint's vertices widen the box: a footprint around (0.85, 0.85) m resets (8, 8).
  layer = nav2.window_at({0.5, 0.5});
  nav2.update(layer, {}, {{0.8, 0.8}, {0.9, 0.8}, {0.9, 0.9}});
  EXPECT_EQ(get(nav2.master(), 8, 8), kCostFree);
  EXPECT_EQ(get(nav2.master(), 1, 1), kCostLethal);  // outside that box now
  // Nothing touched at all: nothing is reset.
  layer = nav2.window_at({0.5, 0.5});
  nav2.update(layer, {}, {});
  EXPECT_EQ(get(nav2.master(), 1, 1), kCostLethal);
}

TEST(Nav2Costmap, TrackUnknownAndOverwrite) {
  Nav2CostmapConfig c = small(true);
  c.track_unknown_space = true;
  Nav2Costmap max(c);
  EXPECT_EQ(get(max.master(), 0, 0), kCostUnknown);
  Costmap2D layer = max.window_at({0.5, 0.5});
  set(layer, 4, 4, kCostLethal);
  max.update(layer, {{0.05, 0.05}}, {});
  EXPECT_EQ(get(max.master(), 4, 4), kCostLethal);
  EXPECT_EQ(get(max.master(), 0, 0), kCostFree);     // inside the box: reset, then the layer's free
  EXPECT_EQ(get(max.master(), 9, 9), kCostUnknown);  // outside: untouched
}

TEST(Nav2Costmap, RollingWindowMovesByWholeCellsAndKeepsTheOverlap) {
  Nav2CostmapConfig c = small(true);
  c.rolling_window = true;
  Nav2Costmap nav2(c);
  Costmap2D layer = nav2.window_at({0.0, 0.0});
  // getSizeInMetersX = (10 - 1 + 0.5) * 0.1 = 0.95: origin -0.475, in whole cells from 0: -0.4.
  EXPECT_NEAR(layer.origin_m.x(), -0.4, 1e-12);
  EXPECT_NEAR(layer.origin_m.y(), -0.4, 1e-12);
  set(layer, 5, 5, kCostLethal);  // (0.15, 0.15) m
  nav2.update(layer, {}, {});
  // 0.3 m along x: new origin 0.3 - 0.475 = -0.175, int((-0.175 + 0.4) / 0.1) = 2 whole cells, to -0.2.
  layer = nav2.window_at({0.3, 0.0});
  EXPECT_NEAR(layer.origin_m.x(), -0.2, 1e-12);
  EXPECT_EQ(get(nav2.master(), 3, 5), kCostLethal);  // the same world cell, 2 cells to the left
  EXPECT_EQ(get(nav2.master(), 5, 5), kCostFree);
  EXPECT_EQ(get(nav2.master(), 9, 5), kCostFree);  // new cells: the default
}

TEST(Nav2Costmap, BadConfigNamesTheKey) {
  Nav2CostmapConfig c = small(true);
  c.resolution_m = 0.0;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = small(true);
  c.combination_method = 2;
  EXPECT_THROW(Nav2Costmap{c}, std::invalid_argument);
  Nav2Costmap nav2(small(true));
  Costmap2D wrong;
  EXPECT_THROW(nav2.update(wrong, {}, {}), std::invalid_argument);
}

}  // namespace
}  // namespace stvl::layer

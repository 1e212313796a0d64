// The grid in the world (origin yaw), the rectangle merge (exactly the occupied cells), the clearance (a lower
// bound within half a cell diagonal of the exact distance) and the drivable cells.
#include "worldgen/occupancy.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tests/worldgen/helpers.hpp"
#include "worldgen/rng.hpp"

namespace stvl::worldgen {
namespace {

using test::grid_from_rows;

TEST(GridFrame, OriginYawTurnsTheGridAboutItsCorner) {
  GridFrame f;
  f.width = 10, f.height = 5, f.resolution_m = 0.1;
  f.origin_x_m = 1.0, f.origin_y_m = 2.0, f.yaw_rad = M_PI / 2;
  // Cell (3, 1)'s centre lies at (0.35, 0.15) in the grid's frame: turned a quarter, (-0.15, 0.35) from the origin.
  const Eigen::Vector2d c = f.cell_center_W({3, 1});
  EXPECT_NEAR(c.x(), 0.85, 1e-12);
  EXPECT_NEAR(c.y(), 2.35, 1e-12);
  const auto back = f.cell_of(c);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->col, 3);
  EXPECT_EQ(back->row, 1);
  EXPECT_FALSE(f.cell_of({1.05, 2.05}));  // beside the origin, on the side the grid does not cover
}

TEST(MergeOccupied, CoversExactlyTheOccupiedCellsWithDisjointRectangles) {
  Rng rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    OccupancyGrid g;
    g.frame.width = 1 + rng.integer(0, 30), g.frame.height = 1 + rng.integer(0, 30);
    g.cells.resize(static_cast<std::size_t>(g.frame.width) * g.frame.height);
    const double density = rng.uniform(0.05, 0.95);
    for (auto& c : g.cells) c = rng.chance(density) ? Cell::kOccupied : rng.chance(0.2) ? Cell::kUnknown : Cell::kFree;
    std::vector<int> covered(g.cells.size(), 0);
    for (const CellRect& r : merge_occupied(g)) {
      ASSERT_GE(r.cols, 1);
      ASSERT_GE(r.rows, 1);
      for (int y = r.row; y < r.row + r.rows; ++y)
        for (int x = r.col; x < r.col + r.cols; ++x) ++covered[g.frame.index({x, y})];
    }
    for (std::size_t i = 0; i < g.cells.size(); ++i)
      ASSERT_EQ(covered[i], g.cells[i] == Cell::kOccupied ? 1 : 0) << "trial " << trial << " cell " << i;
  }
}

TEST(MergeOccupied, WallsBecomeFewBoxes) {
  const OccupancyGrid g = grid_from_rows({"##########", "#........#", "#...##...#", "#...##...#", "##########"});
  EXPECT_EQ(merge_occupied(g).size(), 5u);  // bottom row, two sides, the pillar, the top row
}

TEST(Clearance, IsALowerBoundOfTheDistanceToTheNearestOccupiedSquare) {
  const OccupancyGrid g =
      grid_from_rows({"#.........", "..........", "....#.....", "..........", ".......#..", ".........."}, 0.1);
  const std::vector<float> clearance = clearance_m(g);
  for (int r = 0; r < g.frame.height; ++r)
    for (int c = 0; c < g.frame.width; ++c) {
      const double exact = test::distance_to_occupied(g, g.frame.cell_center_W({c, r}));
      const double got = clearance[g.frame.index({c, r})];
      EXPECT_LE(got, exact + 1e-6) << c << "," << r;
      EXPECT_GE(got, exact - (0.5 * std::sqrt(2.0) - 0.5) * 0.1 - 1e-6) << c << "," << r;
    }
  EXPECT_TRUE(std::isinf(clearance_m(grid_from_rows({"...", "..."}))[0]));
}

TEST(DriveGrid, UnknownAndNearWallCellsAreNotDrivable) {
  const OccupancyGrid g = grid_from_rows({"#.......??", "........??"}, 0.1);
  const DriveGrid d = make_drive_grid(g, 0.25);
  EXPECT_FALSE(d.drivable_at({1, 1}));  // 0.05 m from the wall's square
  EXPECT_FALSE(d.drivable_at({8, 0}));  // unknown
  EXPECT_TRUE(d.drivable_at({5, 0}));
  EXPECT_FALSE(d.drivable_at({-1, 0}));
  EXPECT_TRUE(d.segment_clear(g.frame.cell_center_W({4, 0}), g.frame.cell_center_W({7, 1}), 0.25));
  EXPECT_FALSE(d.segment_clear(g.frame.cell_center_W({4, 0}), g.frame.cell_center_W({9, 0}), 0.25));
}

}  // namespace
}  // namespace stvl::worldgen

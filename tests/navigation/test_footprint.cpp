// nav2's footprint arithmetic (navigation/footprint.hpp) on hand-computed numbers.
#include <cmath>

#include <gtest/gtest.h>

#include "navigation/footprint.hpp"
#include "tests/navigation/grids.hpp"

namespace stvl::navigation {
namespace {

using test::grid;

TEST(Footprint, FromRadiusIs16PointsAndItsInscribedRadiusIsTheEdgeDistance) {
  const auto f = footprint_from_radius(0.22);
  ASSERT_EQ(f.size(), 16u);
  EXPECT_NEAR(f[0].x(), 0.22, 1e-12);
  EXPECT_NEAR(f[4].y(), 0.22, 1e-12);  // 90 degrees
  const auto [inscribed, circumscribed] = inscribed_circumscribed_m(f);
  // The 16-gon's edges are r cos(pi / 16) from the centre: nav2's inscribed radius of a round robot.
  EXPECT_NEAR(inscribed, 0.22 * std::cos(M_PI / 16), 1e-12);
  EXPECT_NEAR(circumscribed, 0.22, 1e-12);
}

TEST(Footprint, RectangleRadii) {
  const std::vector<Eigen::Vector2d> f{{0.3, 0.2}, {-0.3, 0.2}, {-0.3, -0.2}, {0.3, -0.2}};
  const auto [inscribed, circumscribed] = inscribed_circumscribed_m(f);
  EXPECT_NEAR(inscribed, 0.2, 1e-12);
  EXPECT_NEAR(circumscribed, std::hypot(0.3, 0.2), 1e-12);
}

TEST(Footprint, LineIteratorMatchesBresenhamBothEndsIncluded) {
  const auto cells = line_cells(0, 0, 4, 2);
  // deltax 4 >= deltay 2: x every step, y when num (starting at 4 / 2 = 2, +2 each) reaches 4: at steps 1 and 3.
  const std::vector<Eigen::Vector2i> expected{{0, 0}, {1, 1}, {2, 1}, {3, 2}, {4, 2}};
  ASSERT_EQ(cells.size(), expected.size());
  for (std::size_t i = 0; i < cells.size(); ++i) EXPECT_EQ(cells[i], expected[i]) << i;
  EXPECT_EQ(line_cells(3, 3, 3, 3).size(), 1u);
  const auto back = line_cells(0, 5, 0, 1);
  ASSERT_EQ(back.size(), 5u);
  EXPECT_EQ(back.back(), Eigen::Vector2i(0, 1));
}

TEST(Footprint, CostIsTheHighestOnTheOutlineOnly) {
  mapping::Costmap2D m = grid(20, 20, 0.1);
  const std::vector<Eigen::Vector2d> square{{0.25, 0.25}, {-0.25, 0.25}, {-0.25, -0.25}, {0.25, -0.25}};
  const auto placed = place_footprint(square, 1.0, 1.0, 0.0);
  EXPECT_EQ(footprint_cost(m, placed), 0.0);
  m.cells[10 * 20 + 10] = mapping::kCostLethal;  // the centre cell: inside, never read
  EXPECT_EQ(footprint_cost(m, placed), 0.0);
  m.cells[12 * 20 + 9] = 100;  // (0.95, 1.25): on the top edge (y cell 12)
  EXPECT_EQ(footprint_cost(m, placed), 100.0);
  m.cells[7 * 20 + 12] = mapping::kCostLethal;  // (1.25, 0.75): the bottom right corner
  EXPECT_EQ(footprint_cost(m, placed), 254.0);
}

TEST(Footprint, OffTheMapIsLethal) {
  const mapping::Costmap2D m = grid(10, 10, 0.1);
  const auto placed = place_footprint(footprint_from_radius(0.3), 0.1, 0.5, 0.0);  // reaches x = -0.2
  EXPECT_EQ(footprint_cost(m, placed), 254.0);
  int mx, my;
  EXPECT_FALSE(world_to_cell(m, 1.0, 0.5, mx, my));  // the far edge itself is outside
  ASSERT_TRUE(world_to_cell(m, 0.99, 0.5, mx, my));
  EXPECT_EQ(mx, 9);
  EXPECT_EQ(my, 5);
}

TEST(Footprint, PlacedRotates) {
  const auto placed = place_footprint({{1.0, 0.0}}, 2.0, 3.0, M_PI / 2);
  EXPECT_NEAR(placed[0].x(), 2.0, 1e-12);
  EXPECT_NEAR(placed[0].y(), 4.0, 1e-12);
}

}  // namespace
}  // namespace stvl::navigation

// nav2's InflationLayer (navigation2 jazzy f4108e5): computeCost's values, the cell radius's rounding, one obstacle's
// ring of costs, the unknown-cell rules, the propagation against the brute-force reference, and the one grid where
// nav2's propagation does not find the nearest obstacle. Expected costs computed by hand:
// (unsigned char)(252 * exp(-k * (d * resolution - inscribed))).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "navigation/inflation.hpp"
#include "tests/navigation/grids.hpp"

namespace stvl::navigation {
namespace {

using test::cell;
using test::grid;

TEST(Inflation, ComputeCostValues) {
  InflationParams p;  // cost_scaling_factor 10
  EXPECT_EQ(inflation_cost(0.0, 0.05, 0.2, p), 254);
  EXPECT_EQ(inflation_cost(1.0, 0.05, 0.2, p), 253);
  EXPECT_EQ(inflation_cost(std::sqrt(5.0), 0.05, 0.2, p), 253);
  EXPECT_EQ(inflation_cost(4.0, 0.05, 0.2, p), 253);  // 4 * 0.05 == 0.2: the inscribed test is inclusive
  EXPECT_EQ(inflation_cost(5.0, 0.05, 0.2, p), 152);  // 252 * exp(-0.5) = 152.85, truncated
  EXPECT_EQ(inflation_cost(std::hypot(3.0, 4.0), 0.05, 0.2, p), 152);
  EXPECT_EQ(inflation_cost(6.0, 0.05, 0.2, p), 92);  // 252 * exp(-1) = 92.71
  EXPECT_EQ(inflation_cost(11.0, 0.05, 0.2, p), 7);  // 252 * exp(-3.5) = 7.61
  // No cut-off in computeCost itself: 2 m out it is still > 0 with a small scaling factor, 0 with the default.
  InflationParams flat;
  flat.cost_scaling_factor = 0.5;
  EXPECT_EQ(inflation_cost(40.0, 0.05, 0.2, flat), 102);  // 252 * exp(-0.9) = 102.45
  EXPECT_EQ(inflation_cost(40.0, 0.05, 0.2, p), 0);       // 252 * exp(-18) = 3.8e-6
}

TEST(Inflation, CellRadiusRoundsUpLikeCellDistance) {
  EXPECT_EQ(inflation_cell_radius(0.55, 0.05), 11);
  EXPECT_EQ(inflation_cell_radius(0.55, 0.1), 6);  // 5.5 -> 6: cells 0.6 m out are inflated
  EXPECT_EQ(inflation_cell_radius(0.3, 0.05), 6);  // 5.9999999999999991 -> 6
  EXPECT_EQ(inflation_cell_radius(0.0, 0.05), 0);
  EXPECT_EQ(inflation_cell_radius(0.01, 0.05), 1);
}

TEST(Inflation, SingleObstacleRing) {
  auto g = grid(15, 15, 0.05);
  cell(g, 7, 7) = mapping::kCostLethal;
  InflationParams p;
  p.inflation_radius_m = 0.3;  // 6 cells
  inflate(g, 0.1, p);          // inscribed: 2 cells
  EXPECT_EQ(cell(g, 7, 7), 254);
  EXPECT_EQ(cell(g, 8, 7), 253);
  EXPECT_EQ(cell(g, 8, 8), 253);
  EXPECT_EQ(cell(g, 7, 9), 253);   // 2 cells = 0.1 m, inclusive
  EXPECT_EQ(cell(g, 8, 9), 223);   // sqrt(5): 252 * exp(-0.118) = 223.94
  EXPECT_EQ(cell(g, 9, 9), 166);   // sqrt(8): 166.54
  EXPECT_EQ(cell(g, 4, 7), 152);   // 3: 152.85
  EXPECT_EQ(cell(g, 6, 4), 140);   // sqrt(10): 140.93
  EXPECT_EQ(cell(g, 10, 9), 112);  // sqrt(13): 112.92
  EXPECT_EQ(cell(g, 7, 3), 92);    // 4
  EXPECT_EQ(cell(g, 12, 7), 56);   // 5
  EXPECT_EQ(cell(g, 3, 3), 40);    // sqrt(32): 40.49
  EXPECT_EQ(cell(g, 7, 13), 34);   // 6 = the cell radius: still inflated
  EXPECT_EQ(cell(g, 8, 13), 0);    // sqrt(37) = 6.08 > 6: not visited (computeCost would give 32)
  EXPECT_EQ(cell(g, 1, 7), 34);
  EXPECT_EQ(cell(g, 0, 0), 0);
  // Symmetric.
  for (int y = 0; y < 15; ++y)
    for (int x = 0; x < 15; ++x) {
      EXPECT_EQ(cell(g, x, y), cell(g, 14 - x, y));
      EXPECT_EQ(cell(g, x, y), cell(g, y, x));
    }
}

TEST(Inflation, CellRadiusReachesPastTheInflationRadius) {
  auto g = grid(20, 5, 0.1);
  cell(g, 2, 2) = mapping::kCostLethal;
  InflationParams p;
  p.inflation_radius_m = 0.55;  // ceil(5.5) = 6 cells
  p.cost_scaling_factor = 1.0;
  inflate(g, 0.1, p);
  EXPECT_EQ(cell(g, 7, 2), 168);  // 0.5 m: 252 * exp(-0.4) = 168.92
  EXPECT_EQ(cell(g, 8, 2), 152);  // 0.6 m > 0.55 m, within 6 cells: 252 * exp(-0.5)
  EXPECT_EQ(cell(g, 9, 2), 0);
  EXPECT_EQ(cell(g, 8, 3), 0);  // hypot(6, 1) > 6
}

TEST(Inflation, ZeroRadiusChangesNothing) {
  auto g = grid(5, 5, 0.05, mapping::kCostUnknown);
  cell(g, 2, 2) = mapping::kCostLethal;
  const auto before = g.cells;
  InflationParams p;
  p.inflation_radius_m = 0.0;
  p.inflate_around_unknown = true;
  inflate(g, 0.0, p);
  EXPECT_EQ(g.cells, before);
}

TEST(Inflation, KeepsHigherCosts) {
  auto g = grid(9, 1, 0.05);
  cell(g, 0, 0) = mapping::kCostLethal;
  cell(g, 3, 0) = 200;  // above the 152 of 3 cells
  cell(g, 4, 0) = 50;   // below the 92 of 4 cells
  InflationParams p;
  p.inflation_radius_m = 0.3;
  inflate(g, 0.1, p);
  EXPECT_EQ(cell(g, 3, 0), 200);
  EXPECT_EQ(cell(g, 4, 0), 92);
}

TEST(Inflation, UnknownCells) {
  // Lethal at (0, 0); unknown at 1 cell (cost 253), 3 cells (152) and 8 cells (beyond the 6-cell radius).
  auto make = [] {
    auto g = grid(10, 1, 0.05);
    cell(g, 0, 0) = mapping::kCostLethal;
    cell(g, 1, 0) = cell(g, 3, 0) = cell(g, 8, 0) = mapping::kCostUnknown;
    return g;
  };
  InflationParams p;
  p.inflation_radius_m = 0.3;
  auto g = make();
  inflate(g, 0.1, p);  // inflate_unknown false: only costs >= 253 overwrite unknown
  EXPECT_EQ(cell(g, 1, 0), 253);
  EXPECT_EQ(cell(g, 3, 0), 255);
  EXPECT_EQ(cell(g, 2, 0), 253);
  EXPECT_EQ(cell(g, 8, 0), 255);

  p.inflate_unknown = true;  // any cost > 0 overwrites unknown
  g = make();
  inflate(g, 0.1, p);
  EXPECT_EQ(cell(g, 1, 0), 253);
  EXPECT_EQ(cell(g, 3, 0), 152);
  EXPECT_EQ(cell(g, 8, 0), 255);  // not visited

  // A visited unknown cell whose cost truncates to 0 stays unknown even with inflate_unknown.
  InflationParams steep = p;
  steep.cost_scaling_factor = 100.0;  // 3 cells: 252 * exp(-5) = 1.7; 4 cells: 252 * exp(-10) = 0.011
  g = grid(6, 1, 0.05);
  cell(g, 0, 0) = mapping::kCostLethal;
  cell(g, 3, 0) = cell(g, 4, 0) = mapping::kCostUnknown;
  inflate(g, 0.1, steep);
  EXPECT_EQ(cell(g, 3, 0), 1);
  EXPECT_EQ(cell(g, 4, 0), 255);
  EXPECT_EQ(cell(g, 5, 0), 0);

  // inflate_around_unknown: unknown cells are seeds; distance 0 gives 254, which overwrites unknown.
  InflationParams around;
  around.inflation_radius_m = 0.3;
  around.inflate_around_unknown = true;
  g = grid(10, 1, 0.05);
  cell(g, 9, 0) = mapping::kCostUnknown;
  inflate(g, 0.1, around);
  EXPECT_EQ(cell(g, 9, 0), 254);
  EXPECT_EQ(cell(g, 8, 0), 253);
  EXPECT_EQ(cell(g, 6, 0), 152);
  EXPECT_EQ(cell(g, 2, 0), 0);
}

// Random grids of lethal / unknown / free cells with given seed count.
mapping::Costmap2D random_grid(std::mt19937& rng, int seeds, bool with_unknown) {
  auto g = grid(48, 36, 0.05);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(g.cells.size()) - 1);
  std::uniform_int_distribution<int> low_cost(0, 252);
  for (int i = 0; i < 40; ++i) g.cells[pick(rng)] = static_cast<std::uint8_t>(low_cost(rng));
  if (with_unknown)
    for (int i = 0; i < 60; ++i) g.cells[pick(rng)] = mapping::kCostUnknown;
  for (int i = 0; i < seeds; ++i) g.cells[pick(rng)] = mapping::kCostLethal;
  return g;
}

TEST(Inflation, MatchesReferenceWhereThePropagationIsExact) {
  // One seed: every cell within the radius is reached along a staircase that moves away from it, so nav2's
  // propagation gives the exact distance. Seeds farther apart than 2 * radius + 2 cells do not interact.
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    for (bool unknown : {false, true}) {
      InflationParams p;
      p.inflation_radius_m = 0.3 + 0.05 * (trial % 8);
      p.cost_scaling_factor = 2.0 + trial % 10;
      p.inflate_unknown = unknown && trial % 2 == 0;
      p.inflate_around_unknown = false;
      auto g = random_grid(rng, 1, unknown);
      auto a = g, b = g;
      inflate(a, 0.1, p);
      inflate_reference(b, 0.1, p);
      ASSERT_EQ(a.cells, b.cells) << "trial " << trial;
    }
  }
  InflationParams p;  // 0.55 m: 11 cells; seeds 24 cells apart
  auto g = grid(60, 60, 0.05);
  for (int y = 5; y < 60; y += 24)
    for (int x = 3; x < 60; x += 24) cell(g, x, y) = mapping::kCostLethal;
  auto a = g, b = g;
  inflate(a, 0.2, p);
  inflate_reference(b, 0.2, p);
  EXPECT_EQ(a.cells, b.cells);
}

TEST(Inflation, NeverAboveReferenceOnRandomGrids) {
  // Many seeds: a cell takes the source one of its neighbours was reached from, never a nearer one than the
  // nearest, so its cost is at most the reference's; the differences are rare.
  std::mt19937 rng(11);
  std::size_t differing = 0, total = 0;
  for (int trial = 0; trial < 300; ++trial) {
    InflationParams p;
    p.inflation_radius_m = 0.3 + 0.05 * (trial % 6);
    p.cost_scaling_factor = 3.0;
    auto g = random_grid(rng, 2 + trial % 40, false);
    auto a = g, b = g;
    inflate(a, 0.05, p);
    inflate_reference(b, 0.05, p);
    for (std::size_t i = 0; i < g.cells.size(); ++i) {
      ASSERT_LE(a.cells[i], b.cells[i]) << "trial " << trial << " cell " << i;
      differing += a.cells[i] != b.cells[i];
    }
    total += g.cells.size();
  }
  EXPECT_LT(differing * 1000, total);  // under 0.1 %
}

TEST(Inflation, PropagationMissesTheNearestObstacleHere) {
  // Three obstacles; cell (11, 6) is 5 cells from (8, 10) but hypot(1, 5) = 5.10 from (12, 11), and nav2 reaches it
  // only from neighbours that (12, 11) claimed first.
  auto g = grid(16, 16, 0.05);
  cell(g, 6, 8) = cell(g, 8, 10) = cell(g, 12, 11) = mapping::kCostLethal;
  InflationParams p;
  p.inflation_radius_m = 0.4;
  p.cost_scaling_factor = 3.0;
  auto a = g, b = g;
  inflate(a, 0.0, p);
  inflate_reference(b, 0.0, p);
  EXPECT_EQ(cell(b, 11, 6), 119);  // 252 * exp(-3 * 0.25) = 119.04
  EXPECT_EQ(cell(a, 11, 6), 117);  // 252 * exp(-3 * 0.255) = 117.28
  cell(a, 11, 6) = cell(b, 11, 6);
  EXPECT_EQ(a.cells, b.cells);  // the only difference
}

TEST(Inflation, Validation) {
  auto g = grid(4, 4, 0.05);
  InflationParams p;
  EXPECT_NO_THROW(p.validate());
  p.inflation_radius_m = -0.1;
  try {
    p.validate();
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("inflation_radius"), std::string::npos);
  }
  p = InflationParams{};
  p.cost_scaling_factor = std::numeric_limits<double>::quiet_NaN();
  try {
    p.validate();
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cost_scaling_factor"), std::string::npos);
  }
  p = InflationParams{};
  try {
    inflate(g, 0.6, p);  // inscribed 0.6 m > inflation 0.55 m
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("inflation_radius"), std::string::npos);
  }
  EXPECT_THROW(inflate_reference(g, 0.6, p), std::invalid_argument);
  EXPECT_THROW(inflate(g, -1.0, p), std::invalid_argument);
  g.cells.pop_back();
  EXPECT_THROW(inflate(g, 0.2, p), std::invalid_argument);
}

}  // namespace
}  // namespace stvl::navigation

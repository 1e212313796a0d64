// nav2's 2D cell arithmetic (layer/nav2_raytrace.hpp) on hand-made lines and grids: every expected cell is listed
// by hand from nav2's bresenham2D (error starts at da / 2, truncated; each step adds db; the minor coordinate steps
// when the error reaches da, which then comes off), and checked against a plain parametric walk on random lines.
#include "layer/nav2_raytrace.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <utility>
#include <vector>

namespace stvl::layer::nav2 {
namespace {

using Cells = std::vector<std::pair<unsigned, unsigned>>;

Cells as_cells(const std::vector<unsigned>& offsets, unsigned step_x) {
  Cells cells;
  for (unsigned o : offsets) cells.emplace_back(o % step_x, o / step_x);
  return cells;
}

Cells line(unsigned x0, unsigned y0, unsigned x1, unsigned y1, unsigned max_cells = UINT_MAX, unsigned min_cells = 0) {
  constexpr unsigned kStep = 17;
  std::vector<unsigned> offsets;
  raytrace_line(x0, y0, x1, y1, kStep, offsets, max_cells, min_cells);
  return as_cells(offsets, kStep);
}

TEST(Nav2Bresenham, EveryOctantFromTheCentre) {
  // |major| = 4, |minor| = 2: error 2, then 4 (step, 0), 2, 4 (step, 0), 2: the minor offsets are 0 1 1 2 2.
  EXPECT_EQ(line(8, 8, 12, 10), (Cells{{8, 8}, {9, 9}, {10, 9}, {11, 10}, {12, 10}}));  // x+, y+
  EXPECT_EQ(line(8, 8, 10, 12), (Cells{{8, 8}, {9, 9}, {9, 10}, {10, 11}, {10, 12}}));  // y+, x+
  EXPECT_EQ(line(8, 8, 6, 12), (Cells{{8, 8}, {7, 9}, {7, 10}, {6, 11}, {6, 12}}));     // y+, x-
  EXPECT_EQ(line(8, 8, 4, 10), (Cells{{8, 8}, {7, 9}, {6, 9}, {5, 10}, {4, 10}}));      // x-, y+
  EXPECT_EQ(line(8, 8, 4, 6), (Cells{{8, 8}, {7, 7}, {6, 7}, {5, 6}, {4, 6}}));         // x-, y-
  EXPECT_EQ(line(8, 8, 6, 4), (Cells{{8, 8}, {7, 7}, {7, 6}, {6, 5}, {6, 4}}));         // y-, x-
  EXPECT_EQ(line(8, 8, 10, 4), (Cells{{8, 8}, {9, 7}, {9, 6}, {10, 5}, {10, 4}}));      // y-, x+
  EXPECT_EQ(line(8, 8, 12, 6), (Cells{{8, 8}, {9, 7}, {10, 7}, {11, 6}, {12, 6}}));     // x-, y-
}

TEST(Nav2Bresenham, OddMajorDiagonalsAxesAndOneCell) {
  // da 5, db 2: error 2, 4, 6 (step, 1), 3, 5 (step, 0), 2.
  EXPECT_EQ(line(8, 8, 13, 10), (Cells{{8, 8}, {9, 8}, {10, 9}, {11, 9}, {12, 10}, {13, 10}}));
  // Back again: the same error sequence from the other end gives the same cells here (da odd: no halves).
  EXPECT_EQ(line(13, 10, 8, 8), (Cells{{13, 10}, {12, 10}, {11, 9}, {10, 9}, {9, 8}, {8, 8}}));
  // y major, da 3, db 1: error 1, 2, 3 (step, 0), 1.
  EXPECT_EQ(line(8, 8, 9, 11), (Cells{{8, 8}, {8, 9}, {9, 10}, {9, 11}}));
  // |dx| = |dy|: x is major (>=), the error reaches da at every step: a pure diagonal, either way.
  EXPECT_EQ(line(8, 8, 11, 11), (Cells{{8, 8}, {9, 9}, {10, 10}, {11, 11}}));
  EXPECT_EQ(line(8, 8, 5, 11), (Cells{{8, 8}, {7, 9}, {6, 10}, {5, 11}}));
  EXPECT_EQ(line(8, 8, 11, 8), (Cells{{8, 8}, {9, 8}, {10, 8}, {11, 8}}));
  // dx = 0: y major, nav2's sign(0) is -1 for the minor step, which never fires (db = 0).
  EXPECT_EQ(line(8, 8, 8, 5), (Cells{{8, 8}, {8, 7}, {8, 6}, {8, 5}}));
  EXPECT_EQ(line(8, 8, 8, 8), (Cells{{8, 8}}));  // zero length: the one cell
}

TEST(Nav2Bresenham, HalvesStepEarlySoTheDirectionMatters) {
  // da 4 even: the error starts at exactly half, so the minor step comes at the first and third steps, whichever
  // end the walk starts from; the two directions visit different cells.
  EXPECT_EQ(line(0, 0, 4, 2), (Cells{{0, 0}, {1, 1}, {2, 1}, {3, 2}, {4, 2}}));
  EXPECT_EQ(line(4, 2, 0, 0), (Cells{{4, 2}, {3, 1}, {2, 1}, {1, 0}, {0, 0}}));
}

TEST(Nav2Bresenham, BresenhamStepsAreCappedByMaxLength) {
  // bresenham2D directly: da 6, db 0, capped at 2 steps: 3 cells, the start and the last included.
  std::vector<unsigned> visited;
  bresenham_2d(6, 0, 3, 1, 17, 100, 2, visited);
  EXPECT_EQ(visited, (std::vector<unsigned>{100, 101, 102}));
}

TEST(Nav2Raytrace, MaxLengthScalesTheMajorSteps) {
  // dist 8, max 2: scale 0.25, 0.25 * 8 = 2 steps.
  EXPECT_EQ(line(0, 0, 8, 0, 2), (Cells{{0, 0}, {1, 0}, {2, 0}}));
  // dist 10 (6, 8), max 5: scale 0.5, 4 of 8 y steps; db 6, error 4: 10 (x, 2), 8 (x, 0), 6, 12 (x, 4).
  EXPECT_EQ(line(0, 0, 6, 8, 5), (Cells{{0, 0}, {1, 1}, {2, 2}, {2, 3}, {3, 4}}));
  // max 0: no step, the start cell alone (a raytrace_max_range of 0 still clears the origin's cell).
  EXPECT_EQ(line(0, 0, 8, 0, 0), (Cells{{0, 0}}));
  // max past the end: the whole line, end included.
  EXPECT_EQ(line(0, 0, 3, 0, 50), (Cells{{0, 0}, {1, 0}, {2, 0}, {3, 0}}));
}

TEST(Nav2Raytrace, MinLengthMovesTheStartAndKeepsTheFullLinesScale) {
  // 0 + 8 / 8 * 3 = 3: the walk starts at x 3 and goes to the end.
  EXPECT_EQ(line(0, 0, 8, 0, UINT_MAX, 3), (Cells{{3, 0}, {4, 0}, {5, 0}, {6, 0}, {7, 0}, {8, 0}}));
  // min 2, max 4: start 2; the scale 4 / 8 = 0.5 of the *moved* walk's 6 steps is 3: it ends at 5, not at 4.
  EXPECT_EQ(line(0, 0, 8, 0, 4, 2), (Cells{{2, 0}, {3, 0}, {4, 0}, {5, 0}}));
  // Shorter than min (3 < 4): nothing at all.
  EXPECT_TRUE(line(0, 0, 3, 0, UINT_MAX, 4).empty());
  // dist 10, min 5: start (0 + 6 / 10 * 5, 0 + 8 / 10 * 5) = (3, 4); the walk (3, 4) -> (6, 8) on its own
  // differences, y major da 4, db 3: error 2, 5 (x, 1), 4 (x, 0), 3, 6 (x, 2).
  EXPECT_EQ(line(0, 0, 6, 8, UINT_MAX, 5), (Cells{{3, 4}, {4, 5}, {5, 6}, {5, 7}, {6, 8}}));
  // The start truncated: (7 / sqrt(58) * 2, 3 / sqrt(58) * 2) = (1.84, 0.79) -> (1, 0), then (1, 0) -> (7, 3):
  // da 6, db 3, error 3, 6 (y, 0), 3, 6 (y, 0), 3, 6 (y, 0), 3.
  EXPECT_EQ(line(0, 0, 7, 3, UINT_MAX, 2), (Cells{{1, 0}, {2, 1}, {3, 1}, {4, 2}, {5, 2}, {6, 3}, {7, 3}}));
}

TEST(Nav2Raytrace, MatchesThePlainWalkOnRandomLines) {
  // 500 lines on a 64 x 64 grid (seed fixed): the nav2 walk equals the parametric one, and a max length gives a
  // prefix of it, floor(min(1, max / |line|) * |major|) + 1 cells long.
  constexpr unsigned kStep = 64;
  std::mt19937 rng(20250822);
  std::uniform_int_distribution<int> coord(0, 63), max_len(0, 70);
  for (int n = 0; n < 500; ++n) {
    const int x0 = coord(rng), y0 = coord(rng), x1 = coord(rng), y1 = coord(rng);
    std::vector<unsigned> nav2_cells;
    raytrace_line(x0, y0, x1, y1, kStep, nav2_cells);
    const std::vector<unsigned> plain = raytrace_line_reference(x0, y0, x1, y1, kStep);
    ASSERT_EQ(nav2_cells, plain) << "(" << x0 << ", " << y0 << ") -> (" << x1 << ", " << y1 << ")";

    const unsigned max_cells = max_len(rng);
    const double dist = std::hypot(x1 - x0, y1 - y0), major = std::max(std::abs(x1 - x0), std::abs(y1 - y0));
    const double scale = dist == 0.0 ? 1.0 : std::min(1.0, max_cells / dist);
    std::vector<unsigned> capped;
    raytrace_line(x0, y0, x1, y1, kStep, capped, max_cells);
    const std::vector<unsigned> prefix(plain.begin(), plain.begin() + static_cast<long>(scale * major) + 1);
    ASSERT_EQ(capped, prefix) << "max " << max_cells << " on (" << x0 << ", " << y0 << ") -> (" << x1 << ", " << y1
                              << ")";
  }
}

TEST(Nav2Grid, WorldToMapAndBack) {
  const CellGrid g(10, 5, 0.25, -1.0, 2.0);
  unsigned mx = 99, my = 99;
  EXPECT_TRUE(world_to_map(g, -1.0, 2.0, mx, my));  // the origin corner is cell (0, 0)
  EXPECT_EQ(mx, 0u);
  EXPECT_EQ(my, 0u);
  EXPECT_TRUE(world_to_map(g, 1.49, 3.24, mx, my));  // 2.49 / 0.25 = 9.96 -> 9, 1.24 / 0.25 = 4.96 -> 4
  EXPECT_EQ(mx, 9u);
  EXPECT_EQ(my, 4u);
  EXPECT_FALSE(world_to_map(g, 1.5, 2.0, mx, my));      // the far edge: 2.5 / 0.25 = 10, outside
  EXPECT_FALSE(world_to_map(g, -1.0001, 2.0, mx, my));  // left of the origin (truncation would give 0)

  int ix = 0, iy = 0;
  world_to_map_no_bounds(g, -1.3, 2.0, ix, iy);  // -0.3 / 0.25 = -1.2: truncated toward zero, -1 (floor: -2)
  EXPECT_EQ(ix, -1);
  EXPECT_EQ(iy, 0);
  world_to_map_enforce_bounds(g, -5.0, 100.0, ix, iy);
  EXPECT_EQ(ix, 0);
  EXPECT_EQ(iy, 4);
  // Exactly the far edges (0.25 * 10 - 1 = 1.5, 0.25 * 5 + 2 = 3.25): not strictly past, so 10 and 5, one past.
  world_to_map_enforce_bounds(g, 1.5, 3.25, ix, iy);
  EXPECT_EQ(ix, 10);
  EXPECT_EQ(iy, 5);
  world_to_map_enforce_bounds(g, 1.5000001, 3.2500001, ix, iy);
  EXPECT_EQ(ix, 9);
  EXPECT_EQ(iy, 4);

  double wx = 0, wy = 0;
  map_to_world(g, 0, 0, wx, wy);  // cell centres: origin + (m + 0.5) * resolution
  EXPECT_DOUBLE_EQ(wx, -0.875);
  EXPECT_DOUBLE_EQ(wy, 2.125);
  map_to_world(g, -1, 0, wx, wy);  // mapToWorldNoBounds: outside too
  EXPECT_DOUBLE_EQ(wx, -1.125);
}

TEST(Nav2Grid, CellDistanceRoundsTheQuotientUp) {
  const CellGrid g(1, 1, 0.1, 0, 0), g3(1, 1, 0.03, 0, 0);
  EXPECT_EQ(cell_distance(g, 1.0), 10u);    // 10 exactly
  EXPECT_EQ(cell_distance(g, 1.01), 11u);   // 10.1 -> 11
  EXPECT_EQ(cell_distance(g, 0.3), 3u);     // 2.9999999999999996 -> 3
  EXPECT_EQ(cell_distance(g, -1.0), 0u);    // clamped at 0
  EXPECT_EQ(cell_distance(g3, 0.27), 10u);  // 9.000000000000002 -> 10: one more than 0.27 / 0.03 = 9
}

TEST(Nav2Raytrace, RaytraceBounds) {
  Bounds b;
  update_raytrace_bounds(0, 0, 3, 4, 2.5, 0, b);  // |ray| 5, scale 0.5: (1.5, 2)
  EXPECT_DOUBLE_EQ(b.min_x_m, 1.5);
  EXPECT_DOUBLE_EQ(b.max_y_m, 2.0);
  Bounds shorter;
  update_raytrace_bounds(0, 0, 3, 4, 10, 6, shorter);  // 5 < 6: untouched
  EXPECT_GT(shorter.min_x_m, shorter.max_x_m);
  Bounds at_min;
  update_raytrace_bounds(0, 0, 3, 4, 10, 5, at_min);  // 5 is not < 5: the end (3, 4)
  EXPECT_DOUBLE_EQ(at_min.max_x_m, 3.0);
  EXPECT_DOUBLE_EQ(at_min.max_y_m, 4.0);
}

// A 10 x 10 grid at 0.1 m, origin (0, 0), every cell lethal; the cells raytrace_freespace freed.
struct FreespaceRun {
  Cells freed;
  Bounds bounds;
  bool origin_in_map = false;
};
FreespaceRun freespace(double ox, double oy, const Eigen::Matrix3Xf& cloud, double max_m = 100, double min_m = 0,
                       unsigned size_x = 10, unsigned size_y = 10, double res = 0.1) {
  CellGrid g(size_x, size_y, res, 0.0, 0.0, kLethalObstacle);
  FreespaceRun run;
  run.origin_in_map = raytrace_freespace(g, ox, oy, cloud, max_m, min_m, run.bounds);
  for (unsigned y = 0; y < size_y; ++y)
    for (unsigned x = 0; x < size_x; ++x)
      if (g.cost(x, y) == kFreeSpace) run.freed.emplace_back(x, y);
  return run;
}
Eigen::Matrix3Xf points(std::initializer_list<Eigen::Vector3f> ps) {
  Eigen::Matrix3Xf m(3, static_cast<Eigen::Index>(ps.size()));
  Eigen::Index i = 0;
  for (const auto& p : ps) m.col(i++) = p;
  return m;
}

TEST(Nav2Freespace, EndsPastTheGridAreClippedOntoIt) {
  // Right: (0.05, 0.05) -> (2.05, 0.55), a = 2, b = 0.5: t = (1.0 - 0.05) / 2 = 0.475, end (1.0 - 0.001,
  // 0.05 + 0.5 * 0.475 = 0.2875) -> cell (9, 2). Walk (0, 0) -> (9, 2): da 9, db 2, error 4, 6, 8, 10 (y, 1), 3, 5,
  // 7, 9 (y, 0), 2, 4.
  FreespaceRun right = freespace(0.05, 0.05, points({{2.05f, 0.55f, 0.f}}));
  EXPECT_EQ(right.freed, (Cells{{0, 0}, {1, 0}, {2, 0}, {3, 1}, {4, 1}, {5, 1}, {6, 1}, {7, 2}, {8, 2}, {9, 2}}));
  // Bounds: the origin and the clipped end (max range far): x 0.05 .. 0.999, y 0.05 .. 0.2875.
  EXPECT_DOUBLE_EQ(right.bounds.min_x_m, 0.05);
  EXPECT_NEAR(right.bounds.max_x_m, 0.999, 1e-12);
  EXPECT_NEAR(right.bounds.max_y_m, 0.2875, 1e-7);  // float point: 2.05f, 0.55f

  // Below: (0.55, 0.55) -> (0.95, -0.45), a = 0.4, b = -1: t = 0.55, end (0.77, 0.0) exactly on the edge (no
  // 1 mm inside on this side) -> cell (7, 0). Walk y major da 5, db 2, error 2, 4, 6 (x, 1), 3, 5 (x, 0), 2.
  EXPECT_EQ(freespace(0.55, 0.55, points({{0.95f, -0.45f, 0.f}})).freed,
            (Cells{{7, 0}, {7, 1}, {6, 2}, {6, 3}, {5, 4}, {5, 5}}));  // listed row by row
  // Left: (0.55, 0.55) -> (-0.45, 0.8), a = -1, b = 0.25: t = 0.55, end (0, 0.6875) -> cell (0, 6). Walk x major
  // da 5, db 1, error 2, 3, 4, 5 (y, 0), 1, 2.
  EXPECT_EQ(freespace(0.55, 0.55, points({{-0.45f, 0.8f, 0.f}})).freed,
            (Cells{{3, 5}, {4, 5}, {5, 5}, {0, 6}, {1, 6}, {2, 6}}));
  // Past both far edges: (0.05, 0.05) -> (2.05, 4.05): the x clip, then the y clip from the unclipped direction,
  // t = 0.95 / 4 = 0.2375, end (0.05 + 2 * 0.2375 = 0.525, 0.999) -> cell (5, 9).
  const Cells corner = freespace(0.05, 0.05, points({{2.05f, 4.05f, 0.f}})).freed;
  EXPECT_EQ(corner.back(), (std::pair<unsigned, unsigned>{5, 9}));
  EXPECT_EQ(corner.size(), 10u);  // y major, 9 steps: 10 cells

  // The origin off the grid: nothing freed, nothing touched.
  const FreespaceRun off = freespace(-0.05, 0.05, points({{0.55f, 0.05f, 0.f}}));
  EXPECT_FALSE(off.origin_in_map);
  EXPECT_TRUE(off.freed.empty());
  EXPECT_GT(off.bounds.min_x_m, off.bounds.max_x_m);
}

TEST(Nav2Freespace, RaytraceRangesInCells) {
  // 20 x 3 cells at 0.25 m; origin (0.125, 0.375) -> cell (0, 1); the point (4.125, 0.375) -> cell (16, 1).
  const Eigen::Matrix3Xf p = points({{4.125f, 0.375f, 0.f}});
  const auto freed_x = [&](double max_m, double min_m) {
    std::vector<unsigned> xs;
    for (const auto& c : freespace(0.125, 0.375, p, max_m, min_m, 20, 3, 0.25).freed) xs.push_back(c.first);
    return xs;
  };
  // max 1.0 m = 4 cells: scale 4 / 16, 4 steps: cells 0..4.
  EXPECT_EQ(freed_x(1.0, 0.0), (std::vector<unsigned>{0, 1, 2, 3, 4}));
  // max 1.01 m = ceil(4.04) = 5 cells: 5 steps.
  EXPECT_EQ(freed_x(1.01, 0.0), (std::vector<unsigned>{0, 1, 2, 3, 4, 5}));
  // min 0.5 m = 2 cells: the walk starts at 2 and reaches the end 16.
  EXPECT_EQ(freed_x(100, 0.5).front(), 2u);
  EXPECT_EQ(freed_x(100, 0.5).size(), 15u);
  // min 2, max 4 cells: scale 0.25 of the moved walk's 14 steps, 3.5 -> 3: cells 2..5.
  EXPECT_EQ(freed_x(1.0, 0.5), (std::vector<unsigned>{2, 3, 4, 5}));
  // The bounds: the origin and the ray's end pulled in to 1.0 m, (1.125, 0.375).
  const FreespaceRun run = freespace(0.125, 0.375, p, 1.0, 0.0, 20, 3, 0.25);
  EXPECT_DOUBLE_EQ(run.bounds.min_x_m, 0.125);
  EXPECT_DOUBLE_EQ(run.bounds.max_x_m, 1.125);
  EXPECT_DOUBLE_EQ(run.bounds.max_y_m, 0.375);
}

}  // namespace
}  // namespace stvl::layer::nav2

// nav2's NavFn planner (navigation2 jazzy f4108e5, nav2_navfn_planner): the cost translation, hand-computed
// potentials next to the potential's zero cell, straight paths on an empty grid, a wall with a gap, enclosed goals,
// the tolerance search, Dijkstra against A*, and createPlan's failures.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "navigation/inflation.hpp"
#include "navigation/navfn.hpp"
#include "tests/navigation/grids.hpp"

namespace stvl::navigation {
namespace {

using test::cell;
using test::grid;

double length_m(const std::vector<Eigen::Vector2d>& path) {
  double sum = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) sum += (path[i] - path[i - 1]).norm();
  return sum;
}

TEST(Navfn, CostTranslation) {
  EXPECT_EQ(navfn_cost(0, true), 50);
  EXPECT_EQ(navfn_cost(1, true), 50);      // 50.8 truncated
  EXPECT_EQ(navfn_cost(100, true), 130);   // 50 + 80
  EXPECT_EQ(navfn_cost(128, true), 152);   // 152.4
  EXPECT_EQ(navfn_cost(252, true), 251);   // 251.6
  EXPECT_EQ(navfn_cost(253, true), 254);   // inscribed: obstacle
  EXPECT_EQ(navfn_cost(254, true), 254);   // lethal
  EXPECT_EQ(navfn_cost(255, true), 253);   // unknown, allow_unknown: highest passable cost
  EXPECT_EQ(navfn_cost(255, false), 254);  // unknown, not allowed: obstacle
  // setupNavFn makes the border obstacle.
  const std::vector<std::uint8_t> costs(25, 0);
  NavFn nav(5, 5);
  nav.set_costmap(costs.data(), true);
  nav.set_goal(2, 2);
  nav.set_start(2, 3);
  nav.calc_dijkstra(false);
  EXPECT_EQ(nav.cost(0, 2), 254);
  EXPECT_EQ(nav.cost(4, 4), 254);
  EXPECT_EQ(nav.cost(1, 1), 50);
}

TEST(Navfn, PotentialsNextToTheZeroCell) {
  // Free 11 x 11 grid (cost 50 inside the border), potential 0 at (5, 5), full Dijkstra.
  const std::vector<std::uint8_t> costs(121, 0);
  NavFn nav(11, 11);
  nav.set_costmap(costs.data(), true);
  nav.set_goal(5, 5);
  nav.set_start(9, 9);
  EXPECT_TRUE(nav.calc_dijkstra(false));
  EXPECT_EQ(nav.potential(5, 5), 0.0f);
  // Straight neighbours: one neighbour below the other by more than the cost 50 -> 0 + 50.
  EXPECT_FLOAT_EQ(nav.potential(6, 5), 50.0f);
  EXPECT_FLOAT_EQ(nav.potential(5, 4), 50.0f);
  // Diagonal: two neighbours at 50, dc = 0 -> 50 + 50 * 0.7040 = 85.2.
  EXPECT_FLOAT_EQ(nav.potential(6, 6), 85.2f);
  EXPECT_FLOAT_EQ(nav.potential(4, 4), 85.2f);
  // Two cells straight: neighbours 50 and (7, 6) > 100 -> 50 + 50 = 100.
  EXPECT_FLOAT_EQ(nav.potential(7, 5), 100.0f);
  // Knight's move (7, 6): neighbours 85.2 and 100, dc = 14.8, div = 0.296,
  // v = -0.2301 * 0.296^2 + 0.5307 * 0.296 + 0.7040 = 0.840926 -> 85.2 + 50 * 0.840926 = 127.246.
  EXPECT_NEAR(nav.potential(7, 6), 127.246f, 1e-3);
  EXPECT_NEAR(nav.potential(6, 7), 127.246f, 1e-3);
  // Border cells are never reached.
  EXPECT_GE(nav.potential(0, 5), kNavfnPotHigh);
}

TEST(Navfn, StraightPathOnAnEmptyGrid) {
  const auto g = grid(200, 100, 0.05);
  NavfnParams p;
  const PlanResult r = navfn_plan(g, {1.0, 2.5}, {8.0, 2.5}, p);
  ASSERT_TRUE(r.found) << r.failure;
  ASSERT_GE(r.path_W.size(), 2u);
  EXPECT_NEAR(r.path_W.front().x(), 1.0, 1e-9);  // the robot's cell, index 20 * 0.05
  EXPECT_NEAR(r.path_W.back().x(), 8.0, 1e-9);
  for (std::size_t i = 0; i < r.path_W.size(); ++i) {
    EXPECT_NEAR(r.path_W[i].y(), 2.5, 1e-6) << i;
    if (i > 0) {
      EXPECT_GT(r.path_W[i].x(), r.path_W[i - 1].x()) << i;
    }
  }
  EXPECT_NEAR(length_m(r.path_W), 7.0, 1e-6);
  // From the goal cell 160: the propagation stopped when it reached it, its neighbours beyond are unreached, so
  // calcPath follows the grid (whole cells) to 158, then half-cell gradient steps 157.5 ... 21.0; at 21.0 the next
  // position 20.5 rounds (dx = -0.5 -> -1) to the robot's cell 20 (potential 0 < 50), which is appended.
  ASSERT_EQ(r.path_W.size(), 278u);
  const std::size_t n = r.path_W.size();
  EXPECT_NEAR(r.path_W[1].x(), 21 * 0.05, 1e-9);
  EXPECT_NEAR(r.path_W[2].x(), 21.5 * 0.05, 1e-9);
  EXPECT_NEAR(r.path_W[n - 4].x(), 157.5 * 0.05, 1e-9);
  EXPECT_NEAR(r.path_W[n - 3].x(), 158 * 0.05, 1e-9);
  EXPECT_NEAR(r.path_W[n - 2].x(), 159 * 0.05, 1e-9);
  EXPECT_EQ(r.goal_used_W, Eigen::Vector2d(8.0, 2.5));
}

TEST(Navfn, PlannerRoundsToCellIndices) {
  // NavfnPlanner::worldToMap rounds and mapToWorld adds no half cell: the robot at x = 1.03 m (20.6 cells) starts
  // the path at cell 21, x = 1.05 m; Costmap2D::worldToMap (createPlan's checks) floors.
  const auto g = grid(200, 100, 0.05);
  const PlanResult r = navfn_plan(g, {1.03, 2.5}, {8.0, 2.5}, NavfnParams{});
  ASSERT_TRUE(r.found) << r.failure;
  EXPECT_NEAR(r.path_W.front().x(), 1.05, 1e-9);
  // A start in the last half cell of the top row rounds past the grid (nav2 writes outside its arrays): refused.
  const auto small = grid(40, 40, 0.05);
  const PlanResult past = navfn_plan(small, {1.0, 1.99}, {1.0, 1.0}, NavfnParams{});
  EXPECT_FALSE(past.found);
  EXPECT_EQ(past.failure_kind, PlanFailure::kStartOutsideMap);
}

TEST(Navfn, DiagonalPathStaysNearTheLine) {
  const auto g = grid(200, 200, 0.05);
  const Eigen::Vector2d start(1.0, 1.0), goal(8.0, 6.0);
  for (bool astar : {false, true}) {
    NavfnParams p;
    p.use_astar = astar;
    const PlanResult r = navfn_plan(g, start, goal, p);
    ASSERT_TRUE(r.found) << r.failure;
    const Eigen::Vector2d dir = (goal - start).normalized();
    for (const auto& q : r.path_W) {
      const Eigen::Vector2d rel = q - start;
      EXPECT_LT(std::abs(rel.x() * dir.y() - rel.y() * dir.x()), 0.1) << q.transpose();  // 2 cells
    }
    EXPECT_NEAR(length_m(r.path_W), (goal - start).norm(), 0.1);
  }
}

TEST(Navfn, GoesThroughTheGapInAWall) {
  // Wall at x = 5.0 m (cell 100) with a gap of cells 60..79 (y 3.0 - 4.0 m); start and goal low down.
  auto g = grid(200, 100, 0.05);
  for (int y = 0; y < 100; ++y)
    if (y < 60 || y >= 80) cell(g, 100, y) = mapping::kCostLethal;
  InflationParams ip;
  ip.inflation_radius_m = 0.3;
  inflate(g, 0.1, ip);
  for (bool astar : {false, true}) {
    NavfnParams p;
    p.use_astar = astar;
    const PlanResult r = navfn_plan(g, {2.0, 1.0}, {8.0, 1.0}, p);
    ASSERT_TRUE(r.found) << r.failure;
    bool crossed = false;
    for (std::size_t i = 1; i < r.path_W.size(); ++i) {
      if (r.path_W[i - 1].x() < 5.0 && r.path_W[i].x() >= 5.0) {
        crossed = true;
        EXPECT_GT(r.path_W[i].y(), 3.1);  // inside the gap, off its inflated edges
        EXPECT_LT(r.path_W[i].y(), 3.9);
      }
    }
    EXPECT_TRUE(crossed);
    EXPECT_GT(length_m(r.path_W), 2 * std::hypot(3.0, 2.1));  // up to the gap and back down
  }
}

TEST(Navfn, EnclosedGoalHasNoPath) {
  auto g = grid(100, 100, 0.05);
  for (int i = 60; i <= 80; ++i) cell(g, i, 60) = cell(g, i, 80) = cell(g, 60, i) = cell(g, 80, i) = 254;
  NavfnParams p;
  const PlanResult r = navfn_plan(g, {1.0, 1.0}, {3.5, 3.5}, p);
  EXPECT_FALSE(r.found);
  EXPECT_EQ(r.failure_kind, PlanFailure::kNoValidPath);
  EXPECT_NE(r.failure.find("NoValidPathCouldBeFound"), std::string::npos);
  EXPECT_TRUE(r.path_W.empty());
  p.use_astar = true;
  EXPECT_FALSE(navfn_plan(g, {1.0, 1.0}, {3.5, 3.5}, p).found);
}

TEST(Navfn, GoalInAnObstacle) {
  // Lethal block of cells 48..52 around the goal (5.0, 5.0) = rounded cell (50, 50), resolution 0.1.
  auto g = grid(100, 100, 0.1);
  for (int y = 48; y <= 52; ++y)
    for (int x = 48; x <= 52; ++x) cell(g, x, y) = mapping::kCostLethal;
  NavfnParams p;  // tolerance 0.5: the nearest reached point of the scan is 3 cells out, on an axis
  const PlanResult r = navfn_plan(g, {1.0, 1.0}, {5.0, 5.0}, p);
  ASSERT_TRUE(r.found) << r.failure;
  EXPECT_NEAR((r.goal_used_W - Eigen::Vector2d(5.0, 5.0)).norm(), 0.3, 1e-9);
  EXPECT_LT(r.goal_potential, kNavfnPotHigh);
  EXPECT_NEAR((r.path_W.back() - r.goal_used_W).norm(), 0.0, 1e-12);
  p.tolerance_m = 0.2;  // the square reaches only blocked cells
  const PlanResult none = navfn_plan(g, {1.0, 1.0}, {5.0, 5.0}, p);
  EXPECT_FALSE(none.found);
  EXPECT_EQ(none.failure_kind, PlanFailure::kNoValidPath);
  p.tolerance_m = 0.0;  // createPlan refuses a lethal goal outright
  const PlanResult occupied = navfn_plan(g, {1.0, 1.0}, {5.0, 5.0}, p);
  EXPECT_FALSE(occupied.found);
  EXPECT_EQ(occupied.failure_kind, PlanFailure::kGoalOccupied);
  EXPECT_NE(occupied.failure.find("GoalOccupied"), std::string::npos);
  // An inscribed (253) goal passes that check but NavFn treats it as an obstacle: no path without tolerance.
  cell(g, 50, 50) = kCostInscribed;
  for (int y = 48; y <= 52; ++y)
    for (int x = 48; x <= 52; ++x) cell(g, x, y) = kCostInscribed;
  EXPECT_EQ(navfn_plan(g, {1.0, 1.0}, {5.0, 5.0}, p).failure_kind, PlanFailure::kNoValidPath);
}

TEST(Navfn, DijkstraAndAstarAgree) {
  auto g = grid(160, 120, 0.05);
  for (int y = 20; y < 120; ++y) cell(g, 50, y) = mapping::kCostLethal;
  for (int y = 0; y < 90; ++y) cell(g, 110, y) = mapping::kCostLethal;
  inflate(g, 0.1, InflationParams{});
  NavfnParams dijkstra, astar;
  astar.use_astar = true;
  const PlanResult a = navfn_plan(g, {0.5, 5.0}, {7.5, 0.5}, dijkstra);
  const PlanResult b = navfn_plan(g, {0.5, 5.0}, {7.5, 0.5}, astar);
  ASSERT_TRUE(a.found) << a.failure;
  ASSERT_TRUE(b.found) << b.failure;
  EXPECT_NEAR(length_m(a.path_W), length_m(b.path_W), 0.05 * length_m(a.path_W));
  EXPECT_GT(length_m(a.path_W), 7.0);
}

TEST(Navfn, UnknownCellsFollowAllowUnknown) {
  // The only way from left to right crosses a band of unknown cells.
  auto g = grid(100, 40, 0.05);
  for (int y = 0; y < 40; ++y)
    for (int x = 45; x < 55; ++x) cell(g, x, y) = mapping::kCostUnknown;
  NavfnParams p;
  p.tolerance_m = 0.0;
  EXPECT_TRUE(navfn_plan(g, {0.5, 1.0}, {4.5, 1.0}, p).found);
  p.allow_unknown = false;
  const PlanResult r = navfn_plan(g, {0.5, 1.0}, {4.5, 1.0}, p);
  EXPECT_FALSE(r.found);
  EXPECT_EQ(r.failure_kind, PlanFailure::kNoValidPath);
}

TEST(Navfn, StartInAnObstacleIsCleared) {
  auto g = grid(100, 40, 0.05);
  cell(g, 20, 20) = mapping::kCostLethal;  // the robot's rounded cell: clearRobotCell frees it
  const PlanResult r = navfn_plan(g, {1.0, 1.0}, {4.0, 1.0}, NavfnParams{});
  ASSERT_TRUE(r.found) << r.failure;
  EXPECT_EQ(cell(g, 20, 20), mapping::kCostLethal);  // the caller's costmap is untouched
}

TEST(Navfn, CreatePlanChecks) {
  const auto g = grid(40, 40, 0.05);
  NavfnParams p;
  EXPECT_EQ(navfn_plan(g, {-0.1, 1.0}, {1.0, 1.0}, p).failure_kind, PlanFailure::kStartOutsideMap);
  EXPECT_EQ(navfn_plan(g, {1.0, 1.0}, {2.0, 1.0}, p).failure_kind, PlanFailure::kGoalOutsideMap);  // 2.0 / 0.05 = 40
  const PlanResult same = navfn_plan(g, {1.0, 1.0}, {1.0, 1.0}, p);
  ASSERT_TRUE(same.found);
  ASSERT_EQ(same.path_W.size(), 1u);
  EXPECT_EQ(same.path_W[0], Eigen::Vector2d(1.0, 1.0));
  p.use_final_approach_orientation = true;
  const PlanResult up = navfn_plan(g, {1.0, 0.5}, {1.0, 1.5}, p);
  ASSERT_TRUE(up.found) << up.failure;
  ASSERT_TRUE(up.final_yaw.has_value());
  EXPECT_NEAR(*up.final_yaw, M_PI / 2, 1e-6);
  p.tolerance_m = -1.0;
  try {
    navfn_plan(g, {1.0, 1.0}, {1.5, 1.0}, p);
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("tolerance"), std::string::npos);
  }
}

}  // namespace
}  // namespace stvl::navigation

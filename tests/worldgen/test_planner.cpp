// A* and line-of-sight pruning: paths keep the robot's clearance, are nearly as short as the geometry allows,
// and every way a start or goal can be wrong is an error saying so.
#include "worldgen/planner.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/support/invalid_argument.hpp"
#include "tests/worldgen/helpers.hpp"

namespace stvl::worldgen {
namespace {

using test::distance_to_occupied;
using ::testing::HasSubstr;

// A 6 x 4 m room at 0.05 m, walls one cell thick, with a 0.6 m pillar in its middle.
OccupancyGrid room_with_pillar() {
  OccupancyGrid g;
  g.frame.width = 120, g.frame.height = 80, g.frame.resolution_m = 0.05;
  g.cells.assign(120 * 80, Cell::kFree);
  for (int r = 0; r < 80; ++r)
    for (int c = 0; c < 120; ++c) {
      const bool wall = r == 0 || c == 0 || r == 79 || c == 119;
      const bool pillar = c >= 54 && c < 66 && r >= 34 && r < 46;
      if (wall || pillar) g.cells[g.frame.index({c, r})] = Cell::kOccupied;
    }
  return g;
}

// The least exact distance to an occupied square along the polyline, sampled every 5 mm.
double least_clearance(const OccupancyGrid& g, const std::vector<Eigen::Vector2d>& path) {
  double least = 1e9;
  for (std::size_t i = 1; i < path.size(); ++i) {
    const int steps = static_cast<int>((path[i] - path[i - 1]).norm() / 0.005) + 1;
    for (int k = 0; k <= steps; ++k)
      least = std::min(least, distance_to_occupied(g, path[i - 1] + (path[i] - path[i - 1]) * (double(k) / steps)));
  }
  return least;
}

TEST(Planner, PathAroundAPillarKeepsTheRadiusAndIsNearlyShortest) {
  const OccupancyGrid g = room_with_pillar();
  const double radius = 0.34;
  const DriveGrid d = make_drive_grid(g, radius);
  const Eigen::Vector2d start(0.8, 2.0), goal(5.2, 2.0);
  const PlannedPath p = plan_path(d, g.cells, start, goal);
  EXPECT_EQ(p.waypoints_W.front(), start);
  EXPECT_EQ(p.waypoints_W.back(), goal);
  EXPECT_LE(p.waypoints_W.size(), 6u);
  EXPECT_GE(least_clearance(g, p.waypoints_W), radius);
  // Round the 0.6 m pillar: more than the straight 4.4 m, and not much more (the clearance term adds some).
  EXPECT_GT(p.length_m, 4.4);
  EXPECT_LT(p.length_m, 1.2 * 4.4);
  EXPECT_NEAR(p.start_yaw_rad, std::atan2(p.waypoints_W[1].y() - 2.0, p.waypoints_W[1].x() - 0.8), 1e-12);
}

// An L corridor 1.6 m wide at 0.05 m: a leg along x (y 0.1 .. 1.7 m, x 0.1 .. 5.9 m) and a leg along y at its end
// (x 4.3 .. 5.9 m, up to y 4.9 m); everything else occupied.
OccupancyGrid l_corridor() {
  OccupancyGrid g;
  g.frame.width = 120, g.frame.height = 100, g.frame.resolution_m = 0.05;
  g.cells.assign(120 * 100, Cell::kOccupied);
  for (int r = 0; r < 100; ++r)
    for (int c = 0; c < 120; ++c) {
      const bool leg_x = c >= 2 && c < 118 && r >= 2 && r < 34, leg_y = c >= 86 && c < 118 && r >= 2 && r < 98;
      if (leg_x || leg_y) g.cells[g.frame.index({c, r})] = Cell::kFree;
    }
  return g;
}

TEST(Planner, PrunedPathKeepsTheClearanceOfTheCellPath) {
  // The cells keep to the corridor's middle, and so do the pruned legs (down to the band's edge, not the walls).
  const OccupancyGrid g = l_corridor();
  const DriveGrid d = make_drive_grid(g, 0.34);
  const PlannedPath p = plan_path(d, g.cells, Eigen::Vector2d(0.7, 0.9), Eigen::Vector2d(5.1, 4.0));
  EXPECT_GE(least_clearance(g, p.waypoints_W), 0.5);
  EXPECT_LE(p.waypoints_W.size(), 5u);
  EXPECT_LT(p.length_m, 1.1 * (4.4 + 3.1));
}

TEST(Planner, NoCornerCuttingBetweenTwoBlockedCells) {
  const OccupancyGrid g = test::grid_from_rows({"...#", "...#", "#...", "#..."}, 1.0);
  const DriveGrid d = make_drive_grid(g, 0.0);
  const PlannerConfig length_only{0.0, 0.0};  // no clearance term: the shortest way
  // (1, 1) to (2, 2) is a diagonal step between two drivable cells: allowed. A diagonal past a blocked cell is not.
  EXPECT_EQ(astar(d, {1, 1}, {2, 2}, length_only).size(), 2u);
  const OccupancyGrid blocked = test::grid_from_rows({".#", "#."}, 1.0);
  EXPECT_TRUE(astar(make_drive_grid(blocked, 0.0), {0, 1}, {1, 0}, length_only).empty());
}

TEST(Planner, LongestPathEndsAreTheEndsOfAnLCorridor) {
  const OccupancyGrid g = l_corridor();
  const PlannedPath p = plan_path(make_drive_grid(g, 0.34), g.cells, std::nullopt, std::nullopt);
  const Eigen::Vector2d a = p.waypoints_W.front(), b = p.waypoints_W.back();
  // One end at the far end of the leg along x, the other at the top of the leg along y.
  const bool ab = a.x() < 0.6 && b.y() > 4.4, ba = b.x() < 0.6 && a.y() > 4.4;
  EXPECT_TRUE(ab || ba) << a.transpose() << " / " << b.transpose();
  EXPECT_GT(p.length_m, 7.5);
}

TEST(PlannerErrors, StartsAndGoalsThatCannotBeDriven) {
  OccupancyGrid g = room_with_pillar();
  for (int r = 1; r < 79; ++r) g.cells[g.frame.index({90, r})] = Cell::kOccupied;  // a wall parts the room
  for (int r = 60; r < 79; ++r)
    for (int c = 10; c < 30; ++c) g.cells[g.frame.index({c, r})] = Cell::kUnknown;
  const DriveGrid d = make_drive_grid(g, 0.34);
  const auto plan = [&](Eigen::Vector2d s, Eigen::Vector2d t) {
    return stvl::test::invalid_argument_of([&] { plan_path(d, g.cells, s, t, "--start", "--goal"); });
  };
  EXPECT_THAT(plan({0.8, 2.0}, {5.2, 2.0}),
              HasSubstr("--goal (5.200, 2.000) m: unreachable from --start (0.800, 2.000) m"));
  EXPECT_THAT(plan({3.0, 2.0}, {1.0, 1.0}), HasSubstr("--start (3.000, 2.000) m: inside a wall"));
  EXPECT_THAT(plan({-1.0, 2.0}, {1.0, 1.0}), HasSubstr("--start (-1.000, 2.000) m: outside the map"));
  EXPECT_THAT(plan({1.0, 1.0}, {1.0, 3.5}), HasSubstr("--goal (1.000, 3.500) m: in unknown space"));
  EXPECT_THAT(plan({0.1, 1.0}, {1.0, 1.0}), HasSubstr("closer than the robot's 0.34 m"));
  EXPECT_THAT(plan({1.0, 1.0}, {1.01, 1.01}), HasSubstr("lies in the start's cell"));
}

}  // namespace
}  // namespace stvl::worldgen

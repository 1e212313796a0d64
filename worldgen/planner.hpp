#pragma once
// The robot's path through a DriveGrid: A* (8-connected, a clearance term in the cost), line-of-sight pruning
// to few waypoints, and a deterministic long path when no start or goal is given.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "worldgen/occupancy.hpp"

namespace stvl::worldgen {

struct PlannerConfig {
  // A step's cost is its length times 1 + clearance_weight * max(0, 1 - (clearance - radius) / clearance_band_m),
  // so paths keep to the middle of passages narrower than 2 (radius + band) and run straight elsewhere.
  double clearance_weight = 3.0;
  double clearance_band_m = 0.6;
};

// Cheapest path of drivable cells from start to goal (both included); empty when the goal cannot be reached.
// Diagonal steps need both orthogonal neighbours drivable (no corner cutting). Ties break on the cell index, so
// the result is deterministic.
std::vector<CellIndex> astar(const DriveGrid& grid, CellIndex start, CellIndex goal, const PlannerConfig& config = {});

// Line-of-sight pruning: from each kept cell, the farthest later cell that a straight leg reaches through
// drivable cells while keeping at least min(radius + band, the A* path's own least clearance along that stretch)
// from walls (less one cell of rasterisation slack), so that pruning does not pull the path onto the walls.
std::vector<Eigen::Vector2d> simplify_path(const DriveGrid& grid, const std::vector<CellIndex>& cells,
                                           const PlannerConfig& config = {});

// The cells of least (8-connected, octile) path cost from `from` over drivable cells, and the farthest of them;
// ties go to the lower index.
CellIndex farthest_cell(const DriveGrid& grid, CellIndex from);

// The largest drivable region's cell nearest its centroid, then the farthest cell from it (a), then the farthest
// from a (b): a and b are the ends of a longest shortest path (two passes of the search, exact on trees).
std::pair<CellIndex, CellIndex> longest_path_ends(const DriveGrid& grid);

struct PlannedPath {
  std::vector<Eigen::Vector2d> waypoints_W;  // at least two, consecutive points distinct
  double length_m = 0;
  double start_yaw_rad = 0;  // facing the second waypoint
};

// The path from start to goal (world, m). Without a goal: the farthest reachable cell from the start; without a
// start: the farthest from the goal; without both: longest_path_ends. The given points are kept exactly as the
// path's ends. Throws std::invalid_argument saying "<name> (x, y) m: ..." when a point lies outside the grid, in
// a wall, in unknown space or closer than the radius to a wall, or when the goal cannot be reached from the
// start; start_name and goal_name name the points (e.g. "--start").
PlannedPath plan_path(const DriveGrid& grid, const std::vector<Cell>& cells, std::optional<Eigen::Vector2d> start_W,
                      std::optional<Eigen::Vector2d> goal_W, const std::string& start_name = "start",
                      const std::string& goal_name = "goal", const PlannerConfig& config = {});

// Polyline length (m).
double path_length_m(const std::vector<Eigen::Vector2d>& points);

}  // namespace stvl::worldgen

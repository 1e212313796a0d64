#include "worldgen/planner.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <queue>
#include <sstream>
#include <stdexcept>

namespace stvl::worldgen {
namespace {

constexpr int kSteps[8][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {1, -1}, {-1, 1}, {-1, -1}};

using Entry = std::pair<double, std::size_t>;  // (cost, cell index), popped least first, then lower index
using MinQueue = std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>>;

// The drivable neighbours of c (no diagonal between two blocked orthogonal cells) and their step lengths in cells.
template <typename F>
void for_each_step(const DriveGrid& g, CellIndex c, F&& visit) {
  for (const auto& s : kSteps) {
    const CellIndex n{c.col + s[0], c.row + s[1]};
    if (!g.drivable_at(n)) continue;
    if (s[0] != 0 && s[1] != 0 && (!g.drivable_at({c.col + s[0], c.row}) || !g.drivable_at({c.col, c.row + s[1]})))
      continue;
    visit(n, s[0] != 0 && s[1] != 0 ? std::sqrt(2.0) : 1.0);
  }
}

// Octile path cost over the drivable cells from `from` (infinity where unreachable).
std::vector<double> octile_costs(const DriveGrid& g, CellIndex from) {
  std::vector<double> cost(g.drivable.size(), std::numeric_limits<double>::infinity());
  MinQueue open;
  cost[g.frame.index(from)] = 0;
  open.push({0.0, g.frame.index(from)});
  while (!open.empty()) {
    const double c = open.top().first;  // plain variables: a lambda may not capture structured bindings in C++17
    const std::size_t i = open.top().second;
    open.pop();
    if (c > cost[i]) continue;
    for_each_step(g, g.frame.cell(i), [&](CellIndex n, double step) {
      const std::size_t j = g.frame.index(n);
      if (c + step < cost[j]) cost[j] = c + step, open.push({cost[j], j});
    });
  }
  return cost;
}

std::string point_text(const std::string& name, const Eigen::Vector2d& p) {
  std::ostringstream text;
  text.precision(3);
  text << std::fixed << name << " (" << p.x() << ", " << p.y() << ") m";
  return text.str();
}

// The drivable cell holding p_W, or an error saying why it is not one.
CellIndex drivable_cell(const DriveGrid& g, const std::vector<Cell>& cells, const Eigen::Vector2d& p,
                        const std::string& name) {
  const auto c = g.frame.cell_of(p);
  if (!c) {
    std::ostringstream text;
    const Eigen::Vector2d a = g.frame.cell_center_W({0, 0}),
                          b = g.frame.cell_center_W({g.frame.width - 1, g.frame.height - 1});
    text << point_text(name, p) << ": outside the map (its cells run from (" << a.x() << ", " << a.y() << ") to ("
         << b.x() << ", " << b.y() << ") m); give a point on the map";
    throw std::invalid_argument(text.str());
  }
  const std::size_t i = g.frame.index(*c);
  if (cells[i] == Cell::kOccupied)
    throw std::invalid_argument(point_text(name, p) + ": inside a wall (an occupied cell); give a point in free space");
  if (cells[i] == Cell::kUnknown)
    throw std::invalid_argument(point_text(name, p) + ": in unknown space (not drivable); give a point in free space");
  if (!g.drivable[i]) {
    std::ostringstream text;
    text.precision(2);
    text << std::fixed << point_text(name, p) << ": " << g.clearance_m[i]
         << " m from the nearest wall, closer than the robot's " << g.radius_m
         << " m (footprint radius and margin); move it into the open";
    throw std::invalid_argument(text.str());
  }
  return *c;
}

}  // namespace

std::vector<CellIndex> astar(const DriveGrid& g, CellIndex start, CellIndex goal, const PlannerConfig& config) {
  if (!g.drivable_at(start) || !g.drivable_at(goal)) return {};
  const std::size_t n = g.drivable.size(), s = g.frame.index(start), t = g.frame.index(goal);
  std::vector<double> cost(n, std::numeric_limits<double>::infinity());
  std::vector<std::uint32_t> parent(n, std::numeric_limits<std::uint32_t>::max());
  const auto heuristic = [&](CellIndex c) {
    const double dx = std::abs(c.col - goal.col), dy = std::abs(c.row - goal.row);
    return std::max(dx, dy) + (std::sqrt(2.0) - 1.0) * std::min(dx, dy);
  };
  const double band_cells = config.clearance_band_m / g.frame.resolution_m;
  const double radius_cells = g.radius_m / g.frame.resolution_m;
  MinQueue open;
  cost[s] = 0;
  open.push({heuristic(start), s});
  while (!open.empty()) {
    const double f = open.top().first;
    const std::size_t i = open.top().second;
    open.pop();
    if (i == t) break;
    const CellIndex c = g.frame.cell(i);
    if (f - heuristic(c) > cost[i] + 1e-9) continue;  // a stale entry
    for_each_step(g, c, [&](CellIndex m, double step) {
      const std::size_t j = g.frame.index(m);
      const double spare = g.clearance_m[j] / g.frame.resolution_m - radius_cells;
      const double penalty = band_cells > 0 ? std::max(0.0, 1.0 - spare / band_cells) : 0.0;
      const double next = cost[i] + step * (1.0 + config.clearance_weight * penalty);
      if (next < cost[j]) {
        cost[j] = next;
        parent[j] = static_cast<std::uint32_t>(i);
        open.push({next + heuristic(m), j});
      }
    });
  }
  if (!std::isfinite(cost[t])) return {};
  std::vector<CellIndex> path;
  for (std::size_t i = t;; i = parent[i]) {
    path.push_back(g.frame.cell(i));
    if (i == s) break;
  }
  std::reverse(path.begin(), path.end());
  return path;
}

std::vector<Eigen::Vector2d> simplify_path(const DriveGrid& g, const std::vector<CellIndex>& cells,
                                           const PlannerConfig& config) {
  std::vector<Eigen::Vector2d> out;
  if (cells.empty()) return out;
  const auto center = [&](std::size_t k) { return g.frame.cell_center_W(cells[k]); };
  const auto clearance = [&](std::size_t k) { return static_cast<double>(g.clearance_m[g.frame.index(cells[k])]); };
  const double preferred = g.radius_m + config.clearance_band_m;
  out.push_back(center(0));
  std::size_t i = 0;
  while (i + 1 < cells.size()) {
    std::size_t best = i + 1;
    double least = std::min(clearance(i), clearance(i + 1));
    for (std::size_t j = i + 2; j < cells.size(); ++j) {
      least = std::min(least, clearance(j));
      const double required = std::max(g.radius_m, std::min(preferred, least) - g.frame.resolution_m);
      if (!g.segment_clear(center(i), center(j), required)) break;
      best = j;
    }
    out.push_back(center(best));
    i = best;
  }
  return out;
}

CellIndex farthest_cell(const DriveGrid& g, CellIndex from) {
  const std::vector<double> cost = octile_costs(g, from);
  std::size_t best = g.frame.index(from);
  for (std::size_t i = 0; i < cost.size(); ++i)
    if (std::isfinite(cost[i]) && cost[i] > cost[best]) best = i;
  return g.frame.cell(best);
}

std::pair<CellIndex, CellIndex> longest_path_ends(const DriveGrid& g) {
  // The largest 8-connected drivable region (the first found among equals).
  std::vector<int> region(g.drivable.size(), -1);
  std::size_t best_size = 0, best_seed = 0;
  int regions = 0;
  for (std::size_t seed = 0; seed < g.drivable.size(); ++seed) {
    if (!g.drivable[seed] || region[seed] >= 0) continue;
    std::vector<std::size_t> stack{seed};
    region[seed] = regions;
    std::size_t size = 0;
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      ++size;
      for_each_step(g, g.frame.cell(i), [&](CellIndex m, double) {
        const std::size_t j = g.frame.index(m);
        if (region[j] < 0) region[j] = regions, stack.push_back(j);
      });
    }
    if (size > best_size) best_size = size, best_seed = seed;
    ++regions;
  }
  if (best_size == 0)
    throw std::invalid_argument("no drivable cell: every free cell lies closer than the robot's radius to a wall");
  const int chosen = region[best_seed];
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < region.size(); ++i)
    if (region[i] == chosen) sum += Eigen::Vector2d(g.frame.cell(i).col, g.frame.cell(i).row);
  const Eigen::Vector2d centroid = sum / static_cast<double>(best_size);
  std::size_t middle = best_seed;
  double nearest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < region.size(); ++i) {
    if (region[i] != chosen) continue;
    const double d = (Eigen::Vector2d(g.frame.cell(i).col, g.frame.cell(i).row) - centroid).squaredNorm();
    if (d < nearest) nearest = d, middle = i;
  }
  const CellIndex a = farthest_cell(g, g.frame.cell(middle));
  return {a, farthest_cell(g, a)};
}

double path_length_m(const std::vector<Eigen::Vector2d>& points) {
  double length = 0;
  for (std::size_t i = 1; i < points.size(); ++i) length += (points[i] - points[i - 1]).norm();
  return length;
}

PlannedPath plan_path(const DriveGrid& g, const std::vector<Cell>& cells, std::optional<Eigen::Vector2d> start_W,
                      std::optional<Eigen::Vector2d> goal_W, const std::string& start_name,
                      const std::string& goal_name, const PlannerConfig& config) {
  CellIndex start, goal;
  if (start_W) start = drivable_cell(g, cells, *start_W, start_name);
  if (goal_W) goal = drivable_cell(g, cells, *goal_W, goal_name);
  if (start_W && !goal_W) goal = farthest_cell(g, start);
  if (!start_W && goal_W) start = farthest_cell(g, goal);
  if (!start_W && !goal_W) std::tie(start, goal) = longest_path_ends(g);
  if (start == goal) {
    if (start_W && goal_W)
      throw std::invalid_argument(point_text(goal_name, *goal_W) +
                                  ": lies in the start's cell; give two distinct points");
    throw std::invalid_argument("no drivable path: the robot's region holds a single cell (" +
                                point_text(start_name, g.frame.cell_center_W(start)) + ")");
  }
  const std::vector<CellIndex> cells_path = astar(g, start, goal, config);
  if (cells_path.empty())
    throw std::invalid_argument(point_text(goal_name, goal_W.value_or(g.frame.cell_center_W(goal))) +
                                ": unreachable from " +
                                point_text(start_name, start_W.value_or(g.frame.cell_center_W(start))) +
                                " (no passage at least twice the robot's radius wide joins them); move one of them");
  PlannedPath path;
  path.waypoints_W = simplify_path(g, cells_path, config);
  if (start_W) path.waypoints_W.front() = *start_W;
  if (goal_W) path.waypoints_W.back() = *goal_W;
  // Given points inside the first or last pruned leg's cells can coincide with the next waypoint.
  std::vector<Eigen::Vector2d> distinct;
  for (const auto& p : path.waypoints_W)
    if (distinct.empty() || (p - distinct.back()).norm() > 1e-6) distinct.push_back(p);
  if (distinct.size() < 2) distinct = {g.frame.cell_center_W(start), g.frame.cell_center_W(goal)};
  path.waypoints_W = distinct;
  path.length_m = path_length_m(path.waypoints_W);
  const Eigen::Vector2d d = path.waypoints_W[1] - path.waypoints_W[0];
  path.start_yaw_rad = std::atan2(d.y(), d.x());
  return path;
}

}  // namespace stvl::worldgen

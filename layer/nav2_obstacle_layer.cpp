#include "layer/nav2_obstacle_layer.hpp"

#include <cmath>

namespace stvl::layer::nav2 {

std::size_t mark_observation(CellGrid& grid, const Nav2Observation& obs, const ObstacleMarkingParams& params,
                             Bounds& bounds) {
  const bool in_cells = params.range_rule != MarkingRange::kWorld3d;
  const double ox = obs.origin_W.x(), oy = obs.origin_W.y(), oz = obs.origin_W.z();
  // kWorld3d: squared ranges; the cell rules: ranges in cells and the origin's cell (the observation is skipped
  // when its origin is off the grid).
  const double sq_max = obs.obstacle_max_range_m * obs.obstacle_max_range_m;
  const double sq_min = obs.obstacle_min_range_m * obs.obstacle_min_range_m;
  const unsigned max_range_cells = cell_distance(grid, obs.obstacle_max_range_m);
  const unsigned min_range_cells = cell_distance(grid, obs.obstacle_min_range_m);
  unsigned x0 = 0, y0 = 0;
  if (in_cells && !world_to_map(grid, ox, oy, x0, y0)) return 0;

  std::size_t marked = 0;
  for (Eigen::Index i = 0; i < obs.cloud_W.cols(); ++i) {
    const double px = obs.cloud_W(0, i), py = obs.cloud_W(1, i), pz = obs.cloud_W(2, i);
    if (pz < params.min_obstacle_height_m) continue;  // too low
    if (pz > params.max_obstacle_height_m) continue;  // too high

    unsigned mx = 0, my = 0;
    if (!in_cells) {
      const double sq_dist = (px - ox) * (px - ox) + (py - oy) * (py - oy) + (pz - oz) * (pz - oz);
      if (sq_dist >= sq_max) continue;  // too far (a point at the range too)
      if (sq_dist < sq_min) continue;   // too close
      if (!world_to_map(grid, px, py, mx, my)) continue;
    } else {
      if (!world_to_map(grid, px, py, mx, my)) continue;
      if (params.range_rule == MarkingRange::kCellsAndWorld2d) {
        const double wdx = px - ox, wdy = py - oy;
        const double world_dist_sq = wdx * wdx + wdy * wdy;
        if (world_dist_sq > sq_max) continue;  // past the range in metres (a point at it is kept)
        if (world_dist_sq < sq_min) continue;
      }
      // The cell offset's length, truncated, as the clearing walk counts cells.
      const int dx = static_cast<int>(mx) - static_cast<int>(x0);
      const int dy = static_cast<int>(my) - static_cast<int>(y0);
      const auto dist = static_cast<unsigned>(std::hypot(static_cast<double>(dx), static_cast<double>(dy)));
      if (dist > max_range_cells) continue;
      if (dist < min_range_cells) continue;
    }
    grid.costs[grid.index(mx, my)] = kLethalObstacle;
    bounds.touch(px, py);
    ++marked;
  }
  return marked;
}

namespace {

// getMarkingObservations / getClearingObservations: every buffer's observations (purged at now), in order; false
// when any buffer is not current.
bool gather(const std::vector<Nav2ObservationBuffer*>& buffers, std::int64_t now_ns,
            std::vector<std::shared_ptr<const Nav2Observation>>& out) {
  bool current = true;
  for (Nav2ObservationBuffer* buffer : buffers) {
    if (buffer == nullptr) continue;
    buffer->get_observations(now_ns, out);
    current = buffer->is_current(now_ns) && current;
  }
  return current;
}

}  // namespace

bool update_bounds(CellGrid& grid, const std::vector<Nav2ObservationBuffer*>& marking_buffers,
                   const std::vector<Nav2ObservationBuffer*>& clearing_buffers, std::int64_t now_ns,
                   const ObstacleMarkingParams& params, Bounds& bounds) {
  std::vector<std::shared_ptr<const Nav2Observation>> marking, clearing;
  bool current = true;
  current = current && gather(marking_buffers, now_ns, marking);
  current = current && gather(clearing_buffers, now_ns, clearing);  // not gathered when a marking buffer is stale

  for (const auto& obs : clearing) {
    raytrace_freespace(grid, obs->origin_W.x(), obs->origin_W.y(), obs->cloud_W, obs->raytrace_max_range_m,
                       obs->raytrace_min_range_m, bounds);
  }
  for (const auto& obs : marking) mark_observation(grid, *obs, params, bounds);
  return current;
}

}  // namespace stvl::layer::nav2

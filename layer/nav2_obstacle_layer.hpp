#pragma once
// nav2's ObstacleLayer::updateBounds on a plain grid (nav2_costmap_2d/plugins/obstacle_layer.cpp,
// ros-navigation/navigation2 main a3a9704 = jazzy f4108e5): gather the marking observations, then (only if every
// marking buffer was current) the clearing ones; raytrace freespace for every clearing observation; then mark.
// Not here: the rolling window's updateOrigin before, useExtraBounds, static observations, updateFootprint's
// touches after, and updateCosts (footprint clearing, combination into the master).
//
// Marking's range rule changed twice; MarkingRange picks one:
//   kWorld3d (before PR #5697; main 9f4094b, jazzy 31a9911): the squared 3D distance from the sensor origin,
//     z included: skipped when >= obstacle_max_range^2 (strict: a point exactly at the range is not marked) or
//     < obstacle_min_range^2; no check of the origin. Issue #5476: with raytrace_max_range = obstacle_max_range,
//     clearing (in cells, ceil(range / resolution), end cell included) reaches points marking (in metres) skips, so
//     an obstacle the robot reverses away from is cleared when it passes the range.
//   kCells (PR #5697, main 80b72d2, jazzy backport 3320ebf = PR #5775): marking skips the whole observation when
//     its origin is off the grid; a point's distance is the truncated hypot of its cell's offset from the origin's
//     cell, skipped when > cellDistance(obstacle_max_range) or < cellDistance(obstacle_min_range), so a point whose
//     end cell a ray of the same range clears is marked again. (The PR's "do not clear the observation's own cell"
//     was reverted before the merge: clearing is unchanged, and a point beyond obstacle_max_range but within
//     raytrace_max_range is still cleared, by design.)
//   kCellsAndWorld2d (PR #6092, main 8917a13, jazzy 6be3614, for issue #6084): kCells plus, before the cell test, a
//     2D world prefilter: skipped when dx^2 + dy^2 > obstacle_max_range^2 (a point exactly at the range is marked)
//     or < obstacle_min_range^2. nav2 today (the default). It brings #5476 back inside the last cell: a point past
//     obstacle_max_range whose cell a ray of raytrace_max_range = obstacle_max_range reaches is cleared, not marked.
// The height check (layer-level min/max_obstacle_height, on the point's z as a double) is the same in all three:
// skipped when z < min or z > max (both limits marked).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "layer/nav2_observation_buffer.hpp"
#include "layer/nav2_raytrace.hpp"

namespace stvl::layer::nav2 {

enum class MarkingRange { kWorld3d, kCells, kCellsAndWorld2d };

// ObstacleLayer's own parameters that marking reads (defaults as onInitialize declares them).
struct ObstacleMarkingParams {
  double min_obstacle_height_m = 0.0;  // the layer's min_obstacle_height
  double max_obstacle_height_m = 2.0;  // the layer's max_obstacle_height
  MarkingRange range_rule = MarkingRange::kCellsAndWorld2d;
};

// Marks kLethalObstacle at each point of one marking observation that passes the height and range checks, and
// touches the bounds at the point (metres, not the cell). Returns the number of points that marked.
std::size_t mark_observation(CellGrid& grid, const Nav2Observation& observation, const ObstacleMarkingParams& params,
                             Bounds& bounds);

// updateBounds' observations part at now_ns: getMarkingObservations, then getClearingObservations only when every
// marking buffer is current (nav2's `current = current && ...` short-circuits), raytrace_freespace for each clearing
// observation, then mark_observation for each marking one. Buffers in the order of observation_sources (null
// entries skipped; one buffer may be in both lists). Returns the layer's current flag.
bool update_bounds(CellGrid& grid, const std::vector<Nav2ObservationBuffer*>& marking_buffers,
                   const std::vector<Nav2ObservationBuffer*>& clearing_buffers, std::int64_t now_ns,
                   const ObstacleMarkingParams& params, Bounds& bounds);

}  // namespace stvl::layer::nav2

#pragma once
// The robot's footprint as nav2 keeps it, and STVL's update_footprint_enabled: after the costmap is projected
// from the voxel columns, the cells of the footprint's convex fill (at the robot's pose of that update) are set
// free. The voxels themselves stay in the map (STVL clears the layer's 2D costmap only), so voxels of the
// robot's own body become lethal again once the robot has moved off them. Lengths in metres.
#include <array>
#include <vector>

#include <Eigen/Geometry>

#include "mapping/costmap.hpp"

namespace stvl::mapping {

// nav2's footprint for a round robot (makeFootprintFromRadius): 16 points on the circle of radius_m, the first
// on +x, counter-clockwise, in base_link. radius_m must be finite and > 0 (std::invalid_argument).
std::vector<Eigen::Vector2d> footprint_from_radius(double radius_m);

// A footprint in base_link moved to the robot's pose: x, y and yaw of T_world_base (as nav2's
// transformFootprint, which knows no roll or pitch).
std::vector<Eigen::Vector2d> footprint_in_world(const std::vector<Eigen::Vector2d>& footprint_B,
                                                const Eigen::Isometry3d& T_world_base);

// The cells of a polygon's convex fill as nav2's Costmap2D::convexFillCells takes them: each vertex to the cell
// holding it, the outline as grid lines (Bresenham) between consecutive vertex cells, then every cell between
// the lowest and highest outline cell of each column. Cell (ix, iy) covers origin_m + [ix, ix + 1) *
// resolution_m (may be negative: no grid bounds). Fewer than three points: no cells.
std::vector<std::array<int, 2>> footprint_cells(const std::vector<Eigen::Vector2d>& polygon_W,
                                                const Eigen::Vector2d& origin_m, double resolution_m);

// STVL's footprint clearing: the cells of polygon_W's convex fill inside the grid become free.
void clear_footprint(Costmap2D& costmap, const std::vector<Eigen::Vector2d>& polygon_W);

}  // namespace stvl::mapping

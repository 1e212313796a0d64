#pragma once
// The robot's footprint as nav2 uses it around the costmaps (navigation2 jazzy f4108e5): makeFootprintFromRadius,
// calculateMinAndMaxDistances (footprint.cpp), FootprintCollisionChecker::footprintCost with nav2_util's
// LineIterator (footprint_collision_checker.cpp, line_iterator.hpp), and Costmap2D::worldToMap.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "mapping/costmap.hpp"

namespace stvl::navigation {

// makeFootprintFromRadius: 16 points on the circle, the first at angle 0, counter-clockwise.
std::vector<Eigen::Vector2d> footprint_from_radius(double radius_m);
// padFootprint: each coordinate moved away from 0 by padding_m (nav2 keeps the padding as a float).
std::vector<Eigen::Vector2d> pad_footprint(std::vector<Eigen::Vector2d> footprint_m, double padding_m);
// calculateMinAndMaxDistances: the inscribed radius (nearest vertex or edge to the centre) and the circumscribed
// one (farthest). A footprint of fewer than 3 points: (DBL_MAX, 0) as nav2 returns.
std::pair<double, double> inscribed_circumscribed_m(const std::vector<Eigen::Vector2d>& footprint_m);
// The footprint placed at (x, y, yaw) in the costmap's frame (transformFootprint).
std::vector<Eigen::Vector2d> place_footprint(const std::vector<Eigen::Vector2d>& footprint_m, double x_m, double y_m,
                                             double yaw_rad);
// Costmap2D::worldToMap: false left of or below the origin or at or past the far edge.
bool world_to_cell(const mapping::Costmap2D& costmap, double x_m, double y_m, int& mx, int& my);
// FootprintCollisionChecker::footprintCost of a placed footprint: the highest cost along its edges (Bresenham
// lines between consecutive vertices, the last back to the first), 254 as soon as one is lethal or a vertex is off
// the map. Only the outline is read, as nav2 reads it.
double footprint_cost(const mapping::Costmap2D& costmap, const std::vector<Eigen::Vector2d>& placed_W);
// nav2_util::LineIterator's cells from (x0, y0) to (x1, y1), both ends included.
std::vector<Eigen::Vector2i> line_cells(int x0, int y0, int x1, int y1);

}  // namespace stvl::navigation

#pragma once
// nav2's 2D cell arithmetic as its ObstacleLayer uses it, on a plain grid: Costmap2D's world <-> map conversions and
// cellDistance, the Bresenham line walk (raytraceLine / bresenham2D), and ObstacleLayer's raytraceFreespace and
// updateRaytraceBounds. Matched, expression for expression, to ros-navigation/navigation2 nav2_costmap_2d:
//   - src/costmap_2d.cpp (worldToMap*, mapToWorld, cellDistance), main a3a9704 = jazzy f4108e5;
//   - nav2_util/include/nav2_util/raytrace_line_2d.hpp on main a3a9704 (moved there from Costmap2D's header, where
//     jazzy f4108e5 keeps it: include/nav2_costmap_2d/costmap_2d.hpp; the arithmetic is the same);
//   - plugins/obstacle_layer.cpp (raytraceFreespace, updateRaytraceBounds), main a3a9704 = jazzy f4108e5.
// Coordinates in the costmap's global frame (map or odom); a cell's offset is my * size_x_cells + mx.
// raytraceFreespace itself uses only worldToMap (after clipping the end); the NoBounds / EnforceBounds variants are
// what LayeredCostmap::updateMap (EnforceBounds on the layers' bounds, then x0 >= 0, xn = min(size, xn + 1)), the
// clear-costmap service and the range / keepout layers use.
#include <climits>
#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Core>

namespace stvl::layer::nav2 {

// nav2_costmap_2d/cost_values.hpp
constexpr std::uint8_t kFreeSpace = 0;
constexpr std::uint8_t kLethalObstacle = 254;
constexpr std::uint8_t kNoInformation = 255;

// A Costmap2D's cells: size, resolution, the lower left corner of cell (0, 0), costs row by row.
struct CellGrid {
  unsigned size_x_cells = 0, size_y_cells = 0;
  double resolution_m = 0.05;
  double origin_x_m = 0.0, origin_y_m = 0.0;
  std::vector<std::uint8_t> costs;

  CellGrid() = default;
  // size_x_cells * size_y_cells cells of default_cost.
  CellGrid(unsigned size_x_cells, unsigned size_y_cells, double resolution_m, double origin_x_m, double origin_y_m,
           std::uint8_t default_cost = kFreeSpace);
  // Costmap2D::getIndex: the offset of cell (mx, my).
  unsigned index(unsigned mx, unsigned my) const { return my * size_x_cells + mx; }
  std::uint8_t cost(unsigned mx, unsigned my) const { return costs[index(mx, my)]; }
};

// A layer's bounds (updateBounds' min_x, min_y, max_x, max_y, metres), empty as LayeredCostmap starts them.
struct Bounds {
  double min_x_m = std::numeric_limits<double>::max(), min_y_m = std::numeric_limits<double>::max();
  double max_x_m = std::numeric_limits<double>::lowest(), max_y_m = std::numeric_limits<double>::lowest();
  // CostmapLayer::touch: grows the bounds to hold (x_m, y_m).
  void touch(double x_m, double y_m);
};

// Costmap2D::worldToMap: the cell holding (wx_m, wy_m); false (mx, my unspecified) left of or below the origin or
// at or past the far edge (truncation toward zero, so the far edge itself is outside).
bool world_to_map(const CellGrid& grid, double wx_m, double wy_m, unsigned& mx, unsigned& my);
// Costmap2D::mapToWorld / mapToWorldNoBounds: the centre of cell (mx, my), in or out of the grid.
void map_to_world(const CellGrid& grid, int mx, int my, double& wx_m, double& wy_m);
// Costmap2D::worldToMapNoBounds: the cell index truncated toward zero, unchecked (so -0.5 cells gives 0).
void world_to_map_no_bounds(const CellGrid& grid, double wx_m, double wy_m, int& mx, int& my);
// Costmap2D::worldToMapEnforceBounds: 0 left of / below the origin, size - 1 strictly past the far edge, else
// truncated; exactly at the far edge it gives size (one past the grid), as nav2's strict comparison does.
void world_to_map_enforce_bounds(const CellGrid& grid, double wx_m, double wy_m, int& mx, int& my);
// Costmap2D::cellDistance: ceil(world_dist_m / resolution), at least 0 (cells; 0.27 m at 0.03 m gives 10, as the
// floating-point quotient 9.000000000000002 rounds up).
unsigned cell_distance(const CellGrid& grid, double world_dist_m);

// bresenham2D: from offset, abs_da steps (at most max_length_cells) along offset_a, a step along offset_b whenever
// error_b + abs_db reaches abs_da; appends every offset visited, the start and the last one included.
void bresenham_2d(unsigned abs_da, unsigned abs_db, int error_b, int offset_a, int offset_b, unsigned offset,
                  unsigned max_length_cells, std::vector<unsigned>& visited);
// raytraceLine from cell (x0, y0) to cell (x1, y1) on a grid step_x cells wide: appends the offsets visited, in
// order, start and end included. min_length_cells moves the start along the line (truncated to a cell) and walks
// the line from there again; max_length_cells scales the walk by max / |full line| (so with a min length the walk
// ends short of max from the start); nothing when the line is shorter than min_length_cells.
void raytrace_line(unsigned x0, unsigned y0, unsigned x1, unsigned y1, unsigned step_x, std::vector<unsigned>& visited,
                   unsigned max_length_cells = UINT_MAX, unsigned min_length_cells = 0);
// The plain twin of raytrace_line without length limits: for i = 0..max(|dx|, |dy|), the major coordinate x0 + i
// (signed), the minor one the nearest cell to the ideal line, halves rounded toward the end. Offsets on step_x.
std::vector<unsigned> raytrace_line_reference(int x0, int y0, int x1, int y1, unsigned step_x);

// ObstacleLayer::updateRaytraceBounds: touches the ray's end from (ox_m, oy_m) toward (wx_m, wy_m) pulled in to
// max_range_m, nothing when the ray is shorter than min_range_m.
void update_raytrace_bounds(double ox_m, double oy_m, double wx_m, double wy_m, double max_range_m, double min_range_m,
                            Bounds& bounds);
// ObstacleLayer::raytraceFreespace for one clearing observation: from the origin's cell, each point's (x, y) (float,
// as read from a PointCloud2) is clipped to the grid (left/below: onto the origin's edge; right/above: 1 mm inside
// the far edge, the other coordinate from the unshifted edge), then raytrace_line with the ranges in cells sets
// kFreeSpace, end cell included; touches the origin and each ray's update_raytrace_bounds. False, touching nothing,
// when the origin is off the grid.
bool raytrace_freespace(CellGrid& grid, double origin_x_m, double origin_y_m, const Eigen::Matrix3Xf& cloud_W,
                        double raytrace_max_range_m, double raytrace_min_range_m, Bounds& bounds);

}  // namespace stvl::layer::nav2

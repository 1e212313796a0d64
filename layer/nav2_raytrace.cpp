#include "layer/nav2_raytrace.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

// Every expression keeps nav2's operand order and types (int / unsigned / double), so that rounding and truncation
// fall where they fall in nav2 (commits in the header). Where nav2 relies on unsigned wrap-around (an offset plus a
// negative step), the casts below spell it out.

namespace stvl::layer::nav2 {

CellGrid::CellGrid(unsigned size_x, unsigned size_y, double resolution, double origin_x, double origin_y,
                   std::uint8_t default_cost)
    : size_x_cells(size_x),
      size_y_cells(size_y),
      resolution_m(resolution),
      origin_x_m(origin_x),
      origin_y_m(origin_y),
      costs(static_cast<std::size_t>(size_x) * size_y, default_cost) {}

void Bounds::touch(double x_m, double y_m) {
  min_x_m = std::min(x_m, min_x_m);
  min_y_m = std::min(y_m, min_y_m);
  max_x_m = std::max(x_m, max_x_m);
  max_y_m = std::max(y_m, max_y_m);
}

bool world_to_map(const CellGrid& g, double wx_m, double wy_m, unsigned& mx, unsigned& my) {
  if (wx_m < g.origin_x_m || wy_m < g.origin_y_m) return false;
  mx = static_cast<unsigned>((wx_m - g.origin_x_m) / g.resolution_m);
  my = static_cast<unsigned>((wy_m - g.origin_y_m) / g.resolution_m);
  return mx < g.size_x_cells && my < g.size_y_cells;
}

void map_to_world(const CellGrid& g, int mx, int my, double& wx_m, double& wy_m) {
  wx_m = g.origin_x_m + (mx + 0.5) * g.resolution_m;
  wy_m = g.origin_y_m + (my + 0.5) * g.resolution_m;
}

void world_to_map_no_bounds(const CellGrid& g, double wx_m, double wy_m, int& mx, int& my) {
  mx = static_cast<int>((wx_m - g.origin_x_m) / g.resolution_m);
  my = static_cast<int>((wy_m - g.origin_y_m) / g.resolution_m);
}

namespace {

// One axis of worldToMapEnforceBounds: compared before any arithmetic on w, the far edge strictly.
int enforce_axis(double w, double origin, double resolution, unsigned size) {
  if (w < origin) return 0;
  if (w > resolution * size + origin) return static_cast<int>(size) - 1;
  return static_cast<int>((w - origin) / resolution);
}

// nav2's sign(): 1 for a positive difference, -1 otherwise (0 included).
int sign_of(int x) { return x > 0 ? 1 : -1; }

}  // namespace

void world_to_map_enforce_bounds(const CellGrid& g, double wx_m, double wy_m, int& mx, int& my) {
  mx = enforce_axis(wx_m, g.origin_x_m, g.resolution_m, g.size_x_cells);
  my = enforce_axis(wy_m, g.origin_y_m, g.resolution_m, g.size_y_cells);
}

unsigned cell_distance(const CellGrid& g, double world_dist_m) {
  const double cells = std::max(0.0, std::ceil(world_dist_m / g.resolution_m));
  return static_cast<unsigned>(cells);
}

void bresenham_2d(unsigned abs_da, unsigned abs_db, int error_b, int offset_a, int offset_b, unsigned offset,
                  unsigned max_length_cells, std::vector<unsigned>& visited) {
  const unsigned steps = std::min(max_length_cells, abs_da);
  for (unsigned i = 0; i < steps; ++i) {
    visited.push_back(offset);
    offset += static_cast<unsigned>(offset_a);  // wraps for a negative step, as nav2's unsigned offset does
    error_b += static_cast<int>(abs_db);
    if (static_cast<unsigned>(error_b) >= abs_da) {
      offset += static_cast<unsigned>(offset_b);
      error_b -= static_cast<int>(abs_da);
    }
  }
  visited.push_back(offset);  // the last cell, whether the walk was cut short or not
}

void raytrace_line(unsigned x0, unsigned y0, unsigned x1, unsigned y1, unsigned step_x, std::vector<unsigned>& visited,
                   unsigned max_length_cells, unsigned min_length_cells) {
  const int dx_full = static_cast<int>(x1) - static_cast<int>(x0);
  const int dy_full = static_cast<int>(y1) - static_cast<int>(y0);
  // The full line's length decides both limits.
  const double dist = std::hypot(static_cast<double>(dx_full), static_cast<double>(dy_full));
  if (dist < static_cast<double>(min_length_cells)) return;

  // The start moved min_length_cells along the line, truncated; a zero-length line keeps its one cell.
  unsigned start_x = x0, start_y = y0;
  if (dist > 0.0) {
    start_x = static_cast<unsigned>(x0 + dx_full / dist * min_length_cells);
    start_y = static_cast<unsigned>(y0 + dy_full / dist * min_length_cells);
  }
  const unsigned offset = start_y * step_x + start_x;

  // The walk from the moved start, with its own differences.
  const int dx = static_cast<int>(x1) - static_cast<int>(start_x);
  const int dy = static_cast<int>(y1) - static_cast<int>(start_y);
  const unsigned abs_dx = static_cast<unsigned>(std::abs(dx));
  const unsigned abs_dy = static_cast<unsigned>(std::abs(dy));
  const int step_along_x = sign_of(dx);
  const int step_along_y = sign_of(dy) * static_cast<int>(step_x);

  // The fraction of the full line allowed, applied to the moved walk's major difference.
  const double scale = dist == 0.0 ? 1.0 : std::min(1.0, max_length_cells / dist);
  if (abs_dx >= abs_dy) {  // x major (ties too)
    bresenham_2d(abs_dx, abs_dy, static_cast<int>(abs_dx / 2), step_along_x, step_along_y, offset,
                 static_cast<unsigned>(scale * abs_dx), visited);
    return;
  }
  bresenham_2d(abs_dy, abs_dx, static_cast<int>(abs_dy / 2), step_along_y, step_along_x, offset,
               static_cast<unsigned>(scale * abs_dy), visited);
}

std::vector<unsigned> raytrace_line_reference(int x0, int y0, int x1, int y1, unsigned step_x) {
  const long dx = x1 - x0, dy = y1 - y0;
  const long major = std::max(std::labs(dx), std::labs(dy));
  std::vector<unsigned> cells;
  for (long i = 0; i <= major; ++i) {
    // The point at parameter i / major on the segment, each coordinate rounded to the nearest cell, a half toward
    // the end: round(i * d / major) with halves away from the start = floor((2 i |d| + major) / (2 major)).
    long cell[2];
    const long d[2] = {dx, dy};
    for (int a = 0; a < 2; ++a) {
      const long along = major == 0 ? 0 : (2 * i * std::labs(d[a]) + major) / (2 * major);
      cell[a] = (a == 0 ? x0 : y0) + (d[a] < 0 ? -along : along);
    }
    cells.push_back(static_cast<unsigned>(cell[1] * static_cast<long>(step_x) + cell[0]));
  }
  return cells;
}

void update_raytrace_bounds(double ox_m, double oy_m, double wx_m, double wy_m, double max_range_m, double min_range_m,
                            Bounds& bounds) {
  const double dx = wx_m - ox_m, dy = wy_m - oy_m;
  const double full_distance = std::hypot(dx, dy);
  if (full_distance < min_range_m) return;
  const double scale = std::min(1.0, max_range_m / full_distance);
  bounds.touch(ox_m + dx * scale, oy_m + dy * scale);
}

bool raytrace_freespace(CellGrid& grid, double ox, double oy, const Eigen::Matrix3Xf& cloud_W,
                        double raytrace_max_range_m, double raytrace_min_range_m, Bounds& bounds) {
  unsigned x0 = 0, y0 = 0;
  if (!world_to_map(grid, ox, oy, x0, y0)) return false;  // nav2 warns and skips the observation

  const double origin_x = grid.origin_x_m, origin_y = grid.origin_y_m;
  const double map_end_x = origin_x + grid.size_x_cells * grid.resolution_m;
  const double map_end_y = origin_y + grid.size_y_cells * grid.resolution_m;
  bounds.touch(ox, oy);

  const unsigned max_cells = cell_distance(grid, raytrace_max_range_m);
  const unsigned min_cells = cell_distance(grid, raytrace_min_range_m);
  std::vector<unsigned> ray;
  for (Eigen::Index i = 0; i < cloud_W.cols(); ++i) {
    double wx = cloud_W(0, i), wy = cloud_W(1, i);
    // Clip the end onto the grid along the ray, in nav2's order; each step starts from the unclipped direction.
    const double a = wx - ox, b = wy - oy;
    if (wx < origin_x) {
      const double t = (origin_x - ox) / a;
      wx = origin_x;
      wy = oy + b * t;
    }
    if (wy < origin_y) {
      const double t = (origin_y - oy) / b;
      wx = ox + a * t;
      wy = origin_y;
    }
    if (wx > map_end_x) {
      const double t = (map_end_x - ox) / a;
      wx = map_end_x - .001;
      wy = oy + b * t;
    }
    if (wy > map_end_y) {
      const double t = (map_end_y - oy) / b;
      wx = ox + a * t;
      wy = map_end_y - .001;
    }
    unsigned x1 = 0, y1 = 0;
    if (!world_to_map(grid, wx, wy, x1, y1)) continue;  // still off the grid (a corner clipped twice)

    ray.clear();
    raytrace_line(x0, y0, x1, y1, grid.size_x_cells, ray, max_cells, min_cells);
    for (const unsigned offset : ray) grid.costs[offset] = kFreeSpace;  // MarkCell(FREE_SPACE)
    update_raytrace_bounds(ox, oy, wx, wy, raytrace_max_range_m, raytrace_min_range_m, bounds);
  }
  return true;
}

}  // namespace stvl::layer::nav2

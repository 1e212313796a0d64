#include "worldgen/occupancy.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace stvl::worldgen {
namespace {

constexpr double kFar = 1e20;  // "no occupied cell" in the squared distance transform

// Felzenszwalb and Huttenlocher's 1D squared distance transform of f (n samples, stride apart) in place.
void distance_1d(double* f, int n, std::size_t stride, std::vector<double>& d, std::vector<int>& v,
                 std::vector<double>& z) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  d.resize(n), v.resize(n), z.resize(n + 1);
  const auto at = [&](int q) { return f[static_cast<std::size_t>(q) * stride]; };
  const auto meet = [&](int q, int p) {
    return ((at(q) + double(q) * q) - (at(p) + double(p) * p)) / (2.0 * q - 2.0 * p);
  };
  int k = 0;
  v[0] = 0;
  z[0] = -kInf, z[1] = kInf;
  for (int q = 1; q < n; ++q) {
    double s = meet(q, v[k]);
    while (s <= z[k]) s = meet(q, v[--k]);  // z[0] = -inf ends it
    ++k;
    v[k] = q;
    z[k] = s, z[k + 1] = kInf;
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[k + 1] < q) ++k;
    d[q] = double(q - v[k]) * (q - v[k]) + at(v[k]);
  }
  for (int q = 0; q < n; ++q) f[static_cast<std::size_t>(q) * stride] = d[q];
}

}  // namespace

Eigen::Vector2d GridFrame::to_world(const Eigen::Vector2d& p_G) const {
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  return {origin_x_m + c * p_G.x() - s * p_G.y(), origin_y_m + s * p_G.x() + c * p_G.y()};
}

Eigen::Vector2d GridFrame::to_grid(const Eigen::Vector2d& p_W) const {
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  const Eigen::Vector2d d(p_W.x() - origin_x_m, p_W.y() - origin_y_m);
  return {c * d.x() + s * d.y(), -s * d.x() + c * d.y()};
}

Eigen::Vector2d GridFrame::cell_center_W(CellIndex c) const {
  return to_world({(c.col + 0.5) * resolution_m, (c.row + 0.5) * resolution_m});
}

std::optional<CellIndex> GridFrame::cell_of(const Eigen::Vector2d& p_W) const {
  const Eigen::Vector2d g = to_grid(p_W) / resolution_m;
  if (!(g.x() >= 0 && g.y() >= 0 && g.x() < width && g.y() < height)) return std::nullopt;
  return CellIndex{static_cast<int>(std::floor(g.x())), static_cast<int>(std::floor(g.y()))};
}

OccupancyGrid occupancy_from_nav2(const Nav2Map& map) {
  OccupancyGrid grid;
  grid.frame.width = map.width;
  grid.frame.height = map.height;
  grid.frame.resolution_m = map.meta.resolution_m;
  grid.frame.origin_x_m = map.meta.origin_x_m;
  grid.frame.origin_y_m = map.meta.origin_y_m;
  grid.frame.yaw_rad = map.meta.origin_yaw_rad;
  grid.cells.resize(map.data.size());
  for (std::size_t i = 0; i < map.data.size(); ++i)
    grid.cells[i] = map.data[i] == 100 ? Cell::kOccupied : map.data[i] == 0 ? Cell::kFree : Cell::kUnknown;
  return grid;
}

std::vector<CellRect> merge_occupied(const OccupancyGrid& grid) {
  const GridFrame& f = grid.frame;
  std::vector<std::uint8_t> claimed(grid.cells.size(), 0);
  const auto open = [&](int col, int row) {
    const std::size_t i = f.index({col, row});
    return grid.cells[i] == Cell::kOccupied && !claimed[i];
  };
  std::vector<CellRect> rects;
  for (int row = 0; row < f.height; ++row)
    for (int col = 0; col < f.width; ++col) {
      if (!open(col, row)) continue;
      CellRect r{col, row, 1, 1};
      while (r.col + r.cols < f.width && open(r.col + r.cols, row)) ++r.cols;
      while (r.row + r.rows < f.height) {
        bool full = true;
        for (int c = r.col; c < r.col + r.cols && full; ++c) full = open(c, r.row + r.rows);
        if (!full) break;
        ++r.rows;
      }
      for (int y = r.row; y < r.row + r.rows; ++y)
        for (int x = r.col; x < r.col + r.cols; ++x) claimed[f.index({x, y})] = 1;
      rects.push_back(r);
    }
  return rects;
}

std::vector<float> clearance_m(const OccupancyGrid& grid) {
  const GridFrame& f = grid.frame;
  const std::size_t n = grid.cells.size();
  std::vector<float> out(n, std::numeric_limits<float>::infinity());
  if (std::none_of(grid.cells.begin(), grid.cells.end(), [](Cell c) { return c == Cell::kOccupied; })) return out;
  std::vector<double> sq(n);
  for (std::size_t i = 0; i < n; ++i) sq[i] = grid.cells[i] == Cell::kOccupied ? 0.0 : kFar;
  std::vector<double> d, z;
  std::vector<int> v;
  for (int col = 0; col < f.width; ++col) distance_1d(sq.data() + col, f.height, f.width, d, v, z);
  for (int row = 0; row < f.height; ++row)
    distance_1d(sq.data() + static_cast<std::size_t>(row) * f.width, f.width, 1, d, v, z);
  const double half_diagonal = 0.5 * std::sqrt(2.0);
  for (std::size_t i = 0; i < n; ++i)
    out[i] = grid.cells[i] == Cell::kOccupied
                 ? 0.0f
                 : static_cast<float>(std::max(0.0, std::sqrt(sq[i]) - half_diagonal) * f.resolution_m);
  return out;
}

DriveGrid make_drive_grid(const OccupancyGrid& grid, double radius_m) {
  DriveGrid g;
  g.frame = grid.frame;
  g.radius_m = radius_m;
  g.clearance_m = clearance_m(grid);
  g.drivable.resize(grid.cells.size());
  for (std::size_t i = 0; i < grid.cells.size(); ++i)
    g.drivable[i] = grid.cells[i] == Cell::kFree && g.clearance_m[i] >= radius_m ? 1 : 0;
  return g;
}

bool DriveGrid::segment_clear(const Eigen::Vector2d& a_W, const Eigen::Vector2d& b_W, double min_clearance_m) const {
  const double length = (b_W - a_W).norm();
  const int steps = std::max(1, static_cast<int>(std::ceil(length / (0.25 * frame.resolution_m))));
  for (int k = 0; k <= steps; ++k) {
    const auto c = frame.cell_of(a_W + (b_W - a_W) * (static_cast<double>(k) / steps));
    if (!c || !drivable[frame.index(*c)] || clearance_m[frame.index(*c)] < min_clearance_m) return false;
  }
  return true;
}

}  // namespace stvl::worldgen

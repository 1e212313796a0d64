#include "mapping/footprint.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <stdexcept>
#include <string>

namespace stvl::mapping {

std::vector<Eigen::Vector2d> footprint_from_radius(double radius_m) {
  if (!std::isfinite(radius_m) || radius_m <= 0.0)
    throw std::invalid_argument("robot_radius = " + std::to_string(radius_m) + " must be finite and > 0 m");
  constexpr int kPoints = 16;  // nav2's count
  constexpr double kPi = 3.14159265358979323846;
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < kPoints; ++i) {
    const double angle = i * 2.0 * kPi / kPoints;
    points.emplace_back(radius_m * std::cos(angle), radius_m * std::sin(angle));
  }
  return points;
}

std::vector<Eigen::Vector2d> footprint_in_world(const std::vector<Eigen::Vector2d>& footprint_B,
                                                const Eigen::Isometry3d& T_world_base) {
  const Eigen::Vector3d x_axis = T_world_base.linear().col(0);
  const double yaw = std::atan2(x_axis.y(), x_axis.x());
  const Eigen::Rotation2Dd R(yaw);
  const Eigen::Vector2d t = T_world_base.translation().head<2>();
  std::vector<Eigen::Vector2d> polygon_W;
  polygon_W.reserve(footprint_B.size());
  for (const auto& p : footprint_B) polygon_W.push_back(R * p + t);
  return polygon_W;
}

std::vector<std::array<int, 2>> footprint_cells(const std::vector<Eigen::Vector2d>& polygon_W,
                                                const Eigen::Vector2d& origin_m, double resolution_m) {
  if (polygon_W.size() < 3) return {};
  if (!std::isfinite(resolution_m) || resolution_m <= 0.0)
    throw std::invalid_argument("footprint_cells: resolution must be > 0");
  std::vector<std::array<int, 2>> vertices;
  for (const auto& p : polygon_W) {
    if (!p.allFinite()) throw std::invalid_argument("footprint_cells: the polygon must be finite");
    const Eigen::Vector2d c = ((p - origin_m) / resolution_m).array().floor();
    vertices.push_back({static_cast<int>(c.x()), static_cast<int>(c.y())});
  }
  // Lowest and highest outline cell of each column.
  std::map<int, std::array<int, 2>> columns;
  const auto add = [&](int x, int y) {
    auto [it, inserted] = columns.try_emplace(x, std::array<int, 2>{y, y});
    if (!inserted) it->second = {std::min(it->second[0], y), std::max(it->second[1], y)};
  };
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const auto [x0, y0] = vertices[i];
    const auto [x1, y1] = vertices[(i + 1) % vertices.size()];
    // Bresenham along the longer axis, both end cells included.
    const int dx = std::abs(x1 - x0), dy = std::abs(y1 - y0);
    const int sx = x1 >= x0 ? 1 : -1, sy = y1 >= y0 ? 1 : -1;
    const bool x_major = dx >= dy;
    const int steps = x_major ? dx : dy, minor = x_major ? dy : dx;
    int x = x0, y = y0, error = steps / 2;
    for (int s = 0; s <= steps; ++s) {
      add(x, y);
      if (x_major) x += sx;
      else y += sy;
      error -= minor;
      if (error < 0) {
        if (x_major) y += sy;
        else x += sx;
        error += steps;
      }
    }
  }
  std::vector<std::array<int, 2>> cells;
  for (const auto& [x, span] : columns)
    for (int y = span[0]; y <= span[1]; ++y) cells.push_back({x, y});
  return cells;
}

void clear_footprint(Costmap2D& costmap, const std::vector<Eigen::Vector2d>& polygon_W) {
  for (const auto& [ix, iy] : footprint_cells(polygon_W, costmap.origin_m, costmap.resolution_m))
    if (ix >= 0 && iy >= 0 && ix < costmap.width && iy < costmap.height)
      costmap.cells[static_cast<std::size_t>(iy) * costmap.width + ix] = kCostFree;
}

}  // namespace stvl::mapping

#include "navigation/footprint.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace stvl::navigation {
namespace {

// costmap_math.cpp distanceToLine: from (px, py) to the segment (x0, y0)-(x1, y1).
double distance_to_segment(double px, double py, double x0, double y0, double x1, double y1) {
  const double a = px - x0, b = py - y0, c = x1 - x0, d = y1 - y0;
  const double dot = a * c + b * d, len_sq = c * c + d * d;
  const double param = len_sq != 0 ? dot / len_sq : -1;
  double xx, yy;
  if (param < 0) {
    xx = x0, yy = y0;
  } else if (param > 1) {
    xx = x1, yy = y1;
  } else {
    xx = x0 + param * c, yy = y0 + param * d;
  }
  return std::hypot(px - xx, py - yy);
}

}  // namespace

std::vector<Eigen::Vector2d> footprint_from_radius(double radius_m) {
  constexpr int kPoints = 16;
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < kPoints; ++i) {
    const double angle = i * 2 * M_PI / kPoints;
    points.emplace_back(std::cos(angle) * radius_m, std::sin(angle) * radius_m);
  }
  return points;
}

std::vector<Eigen::Vector2d> pad_footprint(std::vector<Eigen::Vector2d> f, double padding_m) {
  const double padding = static_cast<float>(padding_m);  // Costmap2DROS::footprint_padding_ is a float
  const auto sign0 = [](double v) { return v < 0.0 ? -1.0 : v > 0.0 ? 1.0 : 0.0; };
  for (auto& p : f) p += padding * Eigen::Vector2d(sign0(p.x()), sign0(p.y()));
  return f;
}

std::pair<double, double> inscribed_circumscribed_m(const std::vector<Eigen::Vector2d>& f) {
  double min_dist = std::numeric_limits<double>::max(), max_dist = 0.0;
  if (f.size() <= 2) return {min_dist, max_dist};
  for (std::size_t i = 0; i < f.size(); ++i) {
    const Eigen::Vector2d& a = f[i];
    const Eigen::Vector2d& b = f[(i + 1) % f.size()];
    const double vertex = a.norm(), edge = distance_to_segment(0, 0, a.x(), a.y(), b.x(), b.y());
    min_dist = std::min(min_dist, std::min(vertex, edge));
    max_dist = std::max(max_dist, std::max(vertex, edge));
  }
  return {min_dist, max_dist};
}

std::vector<Eigen::Vector2d> place_footprint(const std::vector<Eigen::Vector2d>& f, double x_m, double y_m,
                                             double yaw_rad) {
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  std::vector<Eigen::Vector2d> out;
  out.reserve(f.size());
  for (const auto& p : f) out.emplace_back(x_m + p.x() * c - p.y() * s, y_m + p.x() * s + p.y() * c);
  return out;
}

bool world_to_cell(const mapping::Costmap2D& m, double x_m, double y_m, int& mx, int& my) {
  if (x_m < m.origin_m.x() || y_m < m.origin_m.y()) return false;
  // Truncation toward zero of a non-negative offset, as nav2's (unsigned int) cast.
  const double fx = (x_m - m.origin_m.x()) / m.resolution_m, fy = (y_m - m.origin_m.y()) / m.resolution_m;
  if (!(fx < m.width) || !(fy < m.height)) return false;
  mx = static_cast<int>(fx), my = static_cast<int>(fy);
  return true;
}

std::vector<Eigen::Vector2i> line_cells(int x0, int y0, int x1, int y1) {
  const int deltax = std::abs(x1 - x0), deltay = std::abs(y1 - y0);
  int xinc1 = x1 >= x0 ? 1 : -1, xinc2 = xinc1, yinc1 = y1 >= y0 ? 1 : -1, yinc2 = yinc1;
  int den, num, numadd, numpixels;
  if (deltax >= deltay) {  // at least one x for every y
    xinc1 = 0, yinc2 = 0, den = deltax, num = deltax / 2, numadd = deltay, numpixels = deltax;
  } else {
    xinc2 = 0, yinc1 = 0, den = deltay, num = deltay / 2, numadd = deltax, numpixels = deltay;
  }
  std::vector<Eigen::Vector2i> cells;
  cells.reserve(static_cast<std::size_t>(numpixels) + 1);
  int x = x0, y = y0;
  for (int pixel = 0; pixel <= numpixels; ++pixel) {
    cells.emplace_back(x, y);
    num += numadd;
    if (num >= den) num -= den, x += xinc1, y += yinc1;
    x += xinc2, y += yinc2;
  }
  return cells;
}

double footprint_cost(const mapping::Costmap2D& m, const std::vector<Eigen::Vector2d>& placed) {
  constexpr double kLethal = mapping::kCostLethal;
  if (placed.empty()) return 0.0;
  const auto line_cost = [&](int x0, int y0, int x1, int y1) {
    double cost = 0.0;
    for (const Eigen::Vector2i& c : line_cells(x0, y0, x1, y1)) {
      const double point = m.cells[static_cast<std::size_t>(c.y()) * m.width + c.x()];
      if (point == kLethal) return point;
      cost = std::max(cost, point);
    }
    return cost;
  };
  int x0, y0, x1 = 0, y1 = 0;
  if (!world_to_cell(m, placed[0].x(), placed[0].y(), x0, y0)) return kLethal;
  const int xstart = x0, ystart = y0;
  double cost = 0.0;
  for (std::size_t i = 0; i + 1 < placed.size(); ++i) {
    if (!world_to_cell(m, placed[i + 1].x(), placed[i + 1].y(), x1, y1)) return kLethal;
    cost = std::max(cost, line_cost(x0, y0, x1, y1));
    x0 = x1, y0 = y1;
    if (cost == kLethal) return cost;
  }
  if (placed.size() == 1) x1 = xstart, y1 = ystart;
  return std::max(cost, line_cost(xstart, ystart, x1, y1));
}

}  // namespace stvl::navigation

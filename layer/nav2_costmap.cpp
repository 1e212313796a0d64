#include "layer/nav2_costmap.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace stvl::layer {
namespace {

using mapping::Costmap2D;
using mapping::kCostFree;
using mapping::kCostLethal;
using mapping::kCostUnknown;

void reject(const std::string& key, double value, const std::string& why) {
  throw std::invalid_argument("nav2_costmap." + key + " = " + std::to_string(value) + ": " + why);
}

// Costmap2D::worldToMapEnforceBounds: the cell of (wx, wy), clamped into the grid.
Eigen::Vector2i to_cell_clamped(const Costmap2D& m, const Eigen::Vector2d& p_W) {
  Eigen::Vector2i cell;
  const int size[2] = {m.width, m.height};
  for (int a = 0; a < 2; ++a) {
    const double w = p_W[a], origin = m.origin_m[a];
    if (w < origin) cell[a] = 0;
    else if (w >= m.resolution_m * size[a] + origin) cell[a] = size[a] - 1;
    else cell[a] = static_cast<int>((w - origin) / m.resolution_m);
  }
  return cell;
}

}  // namespace

void Nav2CostmapConfig::validate() const {
  if (!enabled()) return;
  if (!(std::isfinite(width_m) && width_m <= 1000.0)) reject("width_m", width_m, "must lie in (0, 1000] m");
  if (!(std::isfinite(height_m) && height_m <= 1000.0)) reject("height_m", height_m, "must lie in (0, 1000] m");
  if (!(std::isfinite(resolution_m) && resolution_m >= 0.005 && resolution_m <= 1.0))
    reject("resolution_m", resolution_m, "must lie in [0.005, 1] m");
  if (width_m / resolution_m * (height_m / resolution_m) > 1e8) reject("width_m", width_m, "more than 1e8 cells");
  if (combination_method != 0 && combination_method != 1)
    reject("combination_method", combination_method, "STVL's layer combines by 0 (overwrite) or 1 (max) here");
}

Nav2Costmap::Nav2Costmap(const Nav2CostmapConfig& config)
    : config_(config), default_value_(config.track_unknown_space ? kCostUnknown : kCostFree) {
  config_.validate();
  if (!config_.enabled()) throw std::invalid_argument("Nav2Costmap: width_m and height_m must be > 0");
  master_.resolution_m = config_.resolution_m;
  // Costmap2D::resizeMap: cells = metres / resolution (nav2 casts to unsigned int).
  master_.width = static_cast<int>(config_.width_m / config_.resolution_m);
  master_.height = static_cast<int>(config_.height_m / config_.resolution_m);
  master_.width = std::max(master_.width, 1);
  master_.height = std::max(master_.height, 1);
  master_.cells.assign(static_cast<std::size_t>(master_.width) * master_.height, default_value_);
}

Costmap2D Nav2Costmap::window_at(const Eigen::Vector2d& robot_W) {
  if (config_.rolling_window) {
    // LayeredCostmap::updateMap: new origin = robot - getSizeInMeters / 2, getSizeInMetersX = (size - 1 + 0.5) res.
    const double res = master_.resolution_m;
    const Eigen::Vector2d half((master_.width - 1 + 0.5) * res / 2.0, (master_.height - 1 + 0.5) * res / 2.0);
    const Eigen::Vector2d new_origin = robot_W - half;
    // Costmap2D::updateOrigin: whole cells (truncated), the overlapping cells kept, the rest the default.
    const int dx = static_cast<int>((new_origin.x() - master_.origin_m.x()) / res);
    const int dy = static_cast<int>((new_origin.y() - master_.origin_m.y()) / res);
    if (dx != 0 || dy != 0) {
      std::vector<std::uint8_t> moved(master_.cells.size(), default_value_);
      for (int y = 0; y < master_.height; ++y) {
        const int old_y = y + dy;
        if (old_y < 0 || old_y >= master_.height) continue;
        for (int x = 0; x < master_.width; ++x) {
          const int old_x = x + dx;
          if (old_x < 0 || old_x >= master_.width) continue;
          moved[static_cast<std::size_t>(y) * master_.width + x] =
              master_.cells[static_cast<std::size_t>(old_y) * master_.width + old_x];
        }
      }
      master_.cells.swap(moved);
    }
    master_.origin_m += Eigen::Vector2d(dx * res, dy * res);
  }
  Costmap2D layer = master_;
  layer.cells.assign(master_.cells.size(), kCostFree);
  return layer;
}

void Nav2Costmap::update(const Costmap2D& layer, const std::vector<Eigen::Vector2d>& cleared_W,
                         const std::vector<Eigen::Vector2d>& footprint_W) {
  if (layer.width != master_.width || layer.height != master_.height || layer.origin_m != master_.origin_m ||
      layer.cells.size() != master_.cells.size())
    throw std::invalid_argument("Nav2Costmap::update: the layer is not on the window window_at() returned");
  // The bounds STVL's updateBounds touches, as cells (worldToMapEnforceBounds of each point touched).
  Eigen::Vector2i lo(master_.width, master_.height), hi(-1, -1);
  const auto touch = [&](const Eigen::Vector2i& c) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  };
  for (int y = 0; y < layer.height; ++y)
    for (int x = 0; x < layer.width; ++x)
      if (layer.cells[static_cast<std::size_t>(y) * layer.width + x] == kCostLethal) touch({x, y});
  if (config_.touch_cleared_cells)
    for (const auto& p : cleared_W) touch(to_cell_clamped(master_, p));
  for (const auto& p : footprint_W) touch(to_cell_clamped(master_, p));
  // LayeredCostmap::updateMap: [x0, xn + 1) x [y0, yn + 1), nothing when no point was touched.
  const int x0 = std::max(0, lo.x()), y0 = std::max(0, lo.y());
  const int xn = std::min(master_.width, hi.x() + 1), yn = std::min(master_.height, hi.y() + 1);
  if (xn < x0 || yn < y0 || hi.x() < 0) return;
  for (int y = y0; y < yn; ++y)
    for (int x = x0; x < xn; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * master_.width + x;
      std::uint8_t& m = master_.cells[i];
      m = default_value_;  // resetMap
      const std::uint8_t l = layer.cells[i];
      if (l == kCostUnknown) continue;  // both combinations skip the layer's NO_INFORMATION
      if (config_.combination_method == 0 || m == kCostUnknown || m < l) m = l;
    }
}

void Nav2Costmap::combine(const std::vector<std::uint8_t>& layer_cells, int x0, int y0, int xn, int yn,
                          int combination_method) {
  if (layer_cells.size() != master_.cells.size())
    throw std::invalid_argument("Nav2Costmap::combine: the layer's grid is not the master's size");
  if (combination_method < 0 || combination_method > 2)
    throw std::invalid_argument("Nav2Costmap::combine: combination_method " + std::to_string(combination_method));
  x0 = std::max(0, x0), y0 = std::max(0, y0);
  xn = std::min(master_.width, xn), yn = std::min(master_.height, yn);
  for (int y = y0; y < yn; ++y)
    for (int x = x0; x < xn; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * master_.width + x;
      std::uint8_t& m = master_.cells[i];
      m = default_value_;  // resetMap
      const std::uint8_t l = layer_cells[i];
      if (l == kCostUnknown) continue;
      if (combination_method == 0) m = l;
      else if (combination_method == 1 && (m == kCostUnknown || m < l)) m = l;
      else if (combination_method == 2 && m != kCostUnknown && m < l) m = l;
    }
}

std::size_t Nav2Costmap::ghost_cells(const Costmap2D& layer) const {
  std::size_t ghosts = 0;
  for (std::size_t i = 0; i < master_.cells.size() && i < layer.cells.size(); ++i)
    ghosts += master_.cells[i] == kCostLethal && layer.cells[i] != kCostLethal;
  return ghosts;
}

void Nav2Costmap::count_ghosts(double time_s, const Costmap2D& layer) {
  const std::size_t ghosts = ghost_cells(layer);
  ++ghosts_.updates;
  ghosts_.updates_with_ghosts += ghosts > 0;
  ghosts_.last_cells = ghosts;
  if (ghosts > ghosts_.max_cells) ghosts_.max_cells = ghosts, ghosts_.max_at_s = time_s;
}

}  // namespace stvl::layer

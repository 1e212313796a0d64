#include "navigation/costmaps.hpp"

#include <cmath>
#include <stdexcept>

#include "navigation/footprint.hpp"

namespace stvl::navigation {

mapping::Costmap2D static_layer_costmap(const OccupancyMap& map, bool track_unknown_space) {
  // lethal_cost_threshold 100, unknown_cost_value -1: nav2 compares the message's bytes as unsigned char.
  constexpr unsigned kLethalThreshold = 100, kUnknown = 255;
  if (map.width <= 0 || map.height <= 0 || map.data.size() != static_cast<std::size_t>(map.width) * map.height)
    throw std::invalid_argument("static map of " + std::to_string(map.width) + " x " + std::to_string(map.height) +
                                " cells with " + std::to_string(map.data.size()) + " values");
  mapping::Costmap2D m;
  m.width = map.width, m.height = map.height, m.resolution_m = map.resolution_m, m.origin_m = map.origin_m;
  m.cells.resize(map.data.size());
  for (std::size_t i = 0; i < map.data.size(); ++i) {
    const unsigned value = static_cast<std::uint8_t>(map.data[i]);
    if (value == kUnknown) m.cells[i] = track_unknown_space ? mapping::kCostUnknown : mapping::kCostFree;
    else if (value >= kLethalThreshold) m.cells[i] = mapping::kCostLethal;
    else m.cells[i] = mapping::kCostFree;  // trinary_costmap
  }
  return m;
}

NavCostmap::NavCostmap(const CostmapParams& params, double inscribed_radius_m, mapping::Costmap2D base_map)
    : params_(params),
      inscribed_radius_m_(inscribed_radius_m),
      base_(std::move(base_map)),
      default_value_(params.track_unknown_space ? mapping::kCostUnknown : mapping::kCostFree) {
  if (params_.rolling_window) {
    // Costmap2D's size in cells: cellDistance(width) = (unsigned)(width / resolution) (resizeMap in Costmap2DROS).
    base_.width = static_cast<int>(params_.width_m / params_.resolution_m);
    base_.height = static_cast<int>(params_.height_m / params_.resolution_m);
    base_.resolution_m = params_.resolution_m;
    base_.origin_m = Eigen::Vector2d::Zero();  // Costmap2DROS origin_x, origin_y; the first update moves it
    base_.cells.assign(static_cast<std::size_t>(std::max(base_.width, 0)) * std::max(base_.height, 0), default_value_);
  } else if (std::abs(base_.resolution_m - params_.resolution_m) > 1e-9) {
    throw std::invalid_argument("global_costmap.resolution " + std::to_string(params_.resolution_m) +
                                " m differs from the static map's " + std::to_string(base_.resolution_m) + " m");
  }
  if (base_.width <= 0 || base_.height <= 0)
    throw std::invalid_argument("costmap of " + std::to_string(base_.width) + " x " + std::to_string(base_.height) +
                                " cells: width and height must hold at least one cell");
  reset_to_base();
  inflate_now();
}

bool NavCostmap::due(double time_s) const {
  return updates_ == 0 || time_s + 1e-9 >= updated_at_s_ + 1.0 / params_.update_frequency_hz;
}

void NavCostmap::reset_to_base() { combined_ = base_; }

void NavCostmap::update(double time_s, const mapping::Costmap2D& layer_W, const Eigen::Vector2d& robot_W,
                        bool layer_current) {
  current_ = layer_current || was_reset_;
  was_reset_ = false;
  if (params_.rolling_window) {
    // LayeredCostmap::updateMap: new origin = robot - size/2, snapped by Costmap2D::updateOrigin to whole cells
    // from the old origin (the overlap keeps its cells; the window is rebuilt from the layer below anyway).
    const double half_w = 0.5 * base_.width * base_.resolution_m, half_h = 0.5 * base_.height * base_.resolution_m;
    const Eigen::Vector2d old = base_.origin_m;
    // updateOrigin's cell_ox = int((new_origin_x - origin_x_) / resolution_) truncates toward zero.
    const double tx = std::trunc((robot_W.x() - half_w - old.x()) / base_.resolution_m);
    const double ty = std::trunc((robot_W.y() - half_h - old.y()) / base_.resolution_m);
    base_.origin_m = old + Eigen::Vector2d(tx, ty) * base_.resolution_m;
  }
  reset_to_base();
  mapping::Costmap2D& m = combined_;
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width; ++x) {
      const double wx = m.origin_m.x() + (x + 0.5) * m.resolution_m, wy = m.origin_m.y() + (y + 0.5) * m.resolution_m;
      int lx, ly;
      if (!world_to_cell(layer_W, wx, wy, lx, ly)) continue;
      const std::uint8_t value = layer_W.cells[static_cast<std::size_t>(ly) * layer_W.width + lx];
      if (value == mapping::kCostUnknown) continue;  // updateWithMax skips the layer's NO_INFORMATION
      std::uint8_t& old = m.cells[static_cast<std::size_t>(y) * m.width + x];
      if (old == mapping::kCostUnknown || old < value) old = value;
    }
  inflate_now();
  updated_at_s_ = time_s;
  ++updates_;
}

void NavCostmap::clear() {
  reset_to_base();
  inflate_now();
  current_ = false;
  was_reset_ = true;
}

void NavCostmap::inflate_now() {
  inflated_ = combined_;
  inflate(inflated_, inscribed_radius_m_, params_.inflation);
}

}  // namespace stvl::navigation

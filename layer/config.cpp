#include "layer/config.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "layer/nav2_layer.hpp"
#include "layer/stvl_layer.hpp"

namespace stvl::layer {
namespace {

void reject(const std::string& key, double value, const std::string& why) {
  std::ostringstream text;
  text << "nav2_layer." << key << " = " << value << ": " << why;
  throw std::invalid_argument(text.str());
}

}  // namespace

LayerType parse_layer_type(const std::string& text) {
  if (text == "stvl") return LayerType::kStvl;
  if (text == "nav2_voxel") return LayerType::kNav2Voxel;
  if (text == "nav2_obstacle") return LayerType::kNav2Obstacle;
  throw std::invalid_argument("layer_type '" + text + "': expected stvl, nav2_voxel or nav2_obstacle");
}

std::string to_string(LayerType type) {
  switch (type) {
    case LayerType::kNav2Voxel: return "nav2_voxel";
    case LayerType::kNav2Obstacle: return "nav2_obstacle";
    case LayerType::kStvl: break;
  }
  return "stvl";
}

nav2::MarkingRange parse_nav2_marking_range(const std::string& text) {
  if (text == "pre_5697") return nav2::MarkingRange::kWorld3d;
  if (text == "5697") return nav2::MarkingRange::kCells;
  if (text == "6092") return nav2::MarkingRange::kCellsAndWorld2d;
  throw std::invalid_argument("nav2_marking_range '" + text + "': expected pre_5697, 5697 or 6092");
}

std::string to_string(nav2::MarkingRange rule) {
  switch (rule) {
    case nav2::MarkingRange::kWorld3d: return "pre_5697";
    case nav2::MarkingRange::kCells: return "5697";
    case nav2::MarkingRange::kCellsAndWorld2d: break;
  }
  return "6092";
}

void Nav2LayerParams::validate() const {
  if (z_voxels < 1 || z_voxels > static_cast<int>(nav2::kMaxZCells))
    reject("z_voxels", z_voxels, "must lie in [1, 16]: a column is 32 bits, two per level (nav2 would use 16)");
  if (!(std::isfinite(z_resolution_m) && z_resolution_m >= 0.001 && z_resolution_m <= 10.0))
    reject("z_resolution", z_resolution_m, "must lie in [0.001, 10] m");
  if (!std::isfinite(origin_z_m) || std::abs(origin_z_m) > 100.0)
    reject("origin_z", origin_z_m, "must lie in [-100, 100] m");
  if (unknown_threshold < 0 || unknown_threshold > 16)
    reject("unknown_threshold", unknown_threshold, "must lie in [0, 16]");
  if (mark_threshold < 0 || mark_threshold > 16) reject("mark_threshold", mark_threshold, "must lie in [0, 16]");
  if (!std::isfinite(min_obstacle_height_m)) reject("min_obstacle_height", min_obstacle_height_m, "must be finite");
  if (!std::isfinite(max_obstacle_height_m)) reject("max_obstacle_height", max_obstacle_height_m, "must be finite");
  if (combination_method < 0 || combination_method > 2)
    reject("combination_method", combination_method,
           "nav2's layers combine by 0 (overwrite), 1 (max) or 2 (max "
           "without unknown overwrite)");
}

std::unique_ptr<Layer> make_layer(LayerConfig config) {
  if (config.type == LayerType::kStvl) return std::make_unique<StvlLayer>(std::move(config));
  return std::make_unique<Nav2Layer>(std::move(config));
}

}  // namespace stvl::layer

#include "evaluation/config.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace stvl::evaluation {
namespace {

template <typename T>
void require(bool ok, const char* key, T value, const char* rule) {
  if (ok) return;
  std::ostringstream message;
  message << key << " = " << value << " is invalid: " << rule;
  throw std::invalid_argument(message.str());
}

}  // namespace

void EvaluationConfig::validate() const {
  require(std::isfinite(voxel_size_m) && voxel_size_m > 0, "voxel_size", voxel_size_m, "must be finite and > 0 m");
  require(std::isfinite(min_obstacle_height_m) && std::isfinite(max_obstacle_height_m) &&
              min_obstacle_height_m <= max_obstacle_height_m,
          "min_obstacle_height", min_obstacle_height_m, "must be finite and <= max_obstacle_height");
  require(std::isfinite(recall_window_s) && recall_window_s > 0, "recall_window_s", recall_window_s,
          "must be finite and > 0 s");
  require(std::isfinite(evaluate_every_s) && evaluate_every_s > 0, "evaluate_every_s", evaluate_every_s,
          "must be finite and > 0 s");
  require(cameras >= 1 && cameras <= 64, "cameras", cameras, "must lie in 1..64");
  require(tolerance_voxels >= 0 && tolerance_voxels <= 3, "tolerance_voxels", tolerance_voxels, "must lie in 0..3");
  require(min_observed_voxels >= 1, "min_observed_voxels", min_observed_voxels, "must be >= 1");
  require(phantom_min_cells >= 1, "phantom_min_cells", phantom_min_cells, "must be >= 1");
  require(std::isfinite(phantom_clearance_m) && phantom_clearance_m >= 0 && phantom_clearance_m <= 1,
          "phantom_clearance_m", phantom_clearance_m, "must lie in [0, 1] m");
  require(std::isfinite(path_corridor_m) && path_corridor_m >= 0 && path_corridor_m <= 5, "path_corridor_m",
          path_corridor_m, "must lie in [0, 5] m");
}

}  // namespace stvl::evaluation

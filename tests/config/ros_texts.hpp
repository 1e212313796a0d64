#pragma once
// Inline ROS parameter files for the RosParams / RosLint tests: one STVL layer body in the three forms.
#include <fstream>
#include <sstream>
#include <string>

#include "tests/support/command.hpp"

#include "tests/support/invalid_argument.hpp"

namespace stvl::config::test {

using stvl::test::invalid_argument_of;

const std::string kTutorialFile = std::string(STVL_SOURCE_DIR) + "/scenarios/ros/nav2_stvl_tutorial.yaml";

// The nav2 tutorial's values, with obstacle_range per source (where every ROS version reads it).
inline const char* const kLayerBody = R"(enabled: true
voxel_decay: 15.0
decay_model: 0
voxel_size: 0.05
track_unknown_space: true
mark_threshold: 0
update_footprint_enabled: true
combination_method: 1
publish_voxel_map: true
transform_tolerance: 0.2
mapping_mode: false
map_save_duration: 60.0
observation_sources: pointcloud
pointcloud:
  data_type: PointCloud2
  topic: /intel_realsense_r200_depth/points
  marking: true
  clearing: true
  obstacle_range: 3.0
  min_obstacle_height: 0.0
  max_obstacle_height: 2.0
  expected_update_rate: 0.0
  observation_persistence: 0.0
  inf_is_valid: false
  clear_after_reading: true
  max_z: 7.0
  min_z: 0.1
  vertical_fov_angle: 0.8745
  horizontal_fov_angle: 1.048
  decay_acceleration: 15.0
  model_type: 0
)";

inline std::string indented(const std::string& text, int spaces) {
  std::istringstream in(text);
  std::string out;
  for (std::string line; std::getline(in, line);) out += (line.empty() ? "" : std::string(spaces, ' ') + line) + "\n";
  return out;
}

// nav2: the layer under local_costmap: local_costmap: ros__parameters (layer body from line 8).
inline std::string nav2_text(const std::string& body,
                             const std::string& plugin = "spatio_temporal_voxel_layer/SpatioTemporalVoxelLayer") {
  return "local_costmap:\n  local_costmap:\n    ros__parameters:\n      resolution: 0.05\n"
         "      plugins: [\"stvl_layer\"]\n      stvl_layer:\n        plugin: \"" +
         plugin + "\"\n" + indented(body, 8);
}

// move_base: plugins as {name, type} under local_costmap: (layer body from line 6).
inline std::string ros1_text(const std::string& body) {
  return "local_costmap:\n  resolution: 0.05\n  plugins:\n"
         "    - {name: stvl_layer, type: \"spatio_temporal_voxel_layer/SpatioTemporalVoxelLayer\"}\n"
         "  stvl_layer:\n" +
         indented(body, 4);
}

// `message` with every occurrence of `path` written as FILE (so that expected texts need not know the path).
inline std::string file_as_FILE(std::string message, const std::string& path) {
  for (auto pos = message.find(path); !path.empty() && pos != std::string::npos; pos = message.find(path, pos))
    message.replace(pos, path.size(), "FILE");
  return message;
}

// Writes `text` into `dir` as `name`; returns the path.
inline std::string write_file(const stvl::test::TempDir& dir, const std::string& name, const std::string& text) {
  const std::string path = (dir.path() / name).string();
  std::ofstream(path) << text;
  return path;
}

}  // namespace stvl::config::test

#pragma once
// nav2's VoxelLayer or ObstacleLayer read from a nav2 parameter file (ROS 2) and bound to a scenario's cameras: the
// plugin's keys and each observation source's, with the defaults VoxelLayer::onInitialize and
// ObstacleLayer::onInitialize declare (navigation2 jazzy f4108e5), and the enclosing costmap's keys with
// Costmap2DROS's defaults (width 5, height 5, resolution 0.1, rolling_window false, update_frequency 5,
// robot_radius 0.1). Lint findings for them (the keys nav2 does not read, with the nearest name; ranges and bands
// that leave obstacles never cleared or never marked).
#include <optional>
#include <string>
#include <vector>

#include "config/ros_lint.hpp"
#include "layer/config.hpp"
#include "pipeline/pipeline.hpp"

namespace stvl::config {

struct RosNav2Source {
  std::string name, topic, sensor_frame;
  std::string data_type = "LaserScan";  // nav2's default
  int line = 0;                         // 1-based line of its mapping's key
  layer::SourceConfig source;           // marking, clearing, band, persistence, rate; nav2's ranges
};

struct RosNav2Layer {
  std::string file, layer_name, costmap_name, plugin;
  layer::LayerType type = layer::LayerType::kNav2Voxel;
  layer::Nav2LayerParams params;
  bool enabled = true;
  // The costmap, with Costmap2DROS's defaults where the file does not write a key.
  double width_m = 5.0, height_m = 5.0, resolution_m = 0.1, update_frequency_hz = 5.0;
  bool rolling_window = false, track_unknown_space = false;
  std::vector<Eigen::Vector2d> footprint_B;  // the file's footprint, else its robot_radius (nav2's default 0.1 m)
  std::string footprint_source;              // "footprint", "robot_radius" or "nav2's default robot_radius 0.1"
  std::vector<RosNav2Source> sources;
};

// Whether the layer that `layer` / `costmap` pick in the file (the only 3D layer when unnamed) is nav2's VoxelLayer
// or ObstacleLayer. Throws std::invalid_argument as load_ros_stvl_layer() for a file that names none of the three.
bool ros_layer_is_nav2(const std::string& path, const std::string& layer, const std::string& costmap);

// Reads it. Throws std::invalid_argument "file:line: dotted.key: message" for malformed YAML, a value nav2 would
// refuse or the bench cannot run: z_voxels outside 1..16, a resolution or z_resolution <= 0, a range that is NaN or
// negative, a data_type other than PointCloud2 (LaserScan: not simulated), a layer without sources.
RosNav2Layer load_ros_nav2_layer(const std::string& path, const std::string& layer, const std::string& costmap);

// Sets config's layer type, nav2's layer keys, the master costmap (the window), map.voxel_size (the resolution),
// map.update_frequency and the footprint, and binds each source to the camera its topic or sensor_frame names.
// Throws std::invalid_argument for a source bound to no camera or a camera left without one.
void apply_ros_nav2_layer(const RosNav2Layer& layer, pipeline::PipelineConfig& config);

// Lint findings: keys the plugin or a source does not read (the nearest known name), a source whose
// raytrace_max_range is below its obstacle_max_range (marks it never clears), the voxel grid's top under a
// max_obstacle_height (the band is cut), a source's max_obstacle_height at nav2's default 0 (it keeps nothing above
// the floor), a marking range past a rolling window's half width (what is seen farther is lost), inf_is_valid on a
// PointCloud2 source (no effect).
std::vector<LintFinding> lint_ros_nav2_layer(const std::string& path, const std::string& layer,
                                             const std::string& costmap);

}  // namespace stvl::config

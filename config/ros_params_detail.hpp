#pragma once
// Shared by ros_params.cpp and ros_lint.cpp (not a public header): where the layer sits in the file, and the
// keys each ROS version of STVL reads (spatio_temporal_voxel_layer.cpp, onInitialize(), on the ros2 and
// noetic-devel / melodic-devel branches).
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "config/ros_params.hpp"
#include "config/yaml_reader.hpp"

namespace stvl::config::ros_detail {

// pluginlib's lookup name (and the class name pluginlib also accepts).
inline const char* const kStvlPlugin = "spatio_temporal_voxel_layer/SpatioTemporalVoxelLayer";
inline const char* const kStvlClass = "spatio_temporal_voxel_layer::SpatioTemporalVoxelLayer";
// nav2's own 3D and 2D layers (nav2_costmap_2d), which the bench runs too (layer/nav2_layer.hpp).
inline const char* const kNav2VoxelPlugin = "nav2_costmap_2d::VoxelLayer";
inline const char* const kNav2ObstaclePlugin = "nav2_costmap_2d::ObstacleLayer";

struct LayerNodes {
  RosFlavour flavour = RosFlavour::kBare;
  std::string layer_name, costmap_name;
  YAML::Node layer;          // the layer's mapping
  std::string layer_path;    // dotted prefix of the layer's keys in messages ("stvl_layer"; "" for a bare file)
  int layer_line = 1;        // line of the layer's own key (1 for a bare file)
  YAML::Node costmap;        // the costmap's parameters (null node for a bare file)
  std::string costmap_path;  // "local_costmap"
  std::string plugin;        // the layer's plugin type as written (STVL's, or nav2's VoxelLayer / ObstacleLayer)
  // ROS 1's searchParam() chain above the layer (obstacle_range): the costmap's mapping, then the root.
  std::vector<YAML::Node> search_chain;
};

// Finds the layer (see load_ros_stvl_layer): STVL's or, unless stvl_only, nav2's VoxelLayer or ObstacleLayer (an
// unnamed layer: the only one of the three); throws std::invalid_argument.
LayerNodes locate_layer(const YAML::Node& root, const std::string& file, const std::string& layer,
                        const std::string& costmap, bool stvl_only = true);
// Whether a plugin type is nav2's VoxelLayer or ObstacleLayer.
bool is_nav2_layer(const std::string& plugin);

// 1-based line of `key` in mapping `map`; 0 when absent (or `map` is not a mapping).
int key_line(const YAML::Node& map, const std::string& key);
// "prefix.key", or "key" for an empty prefix.
std::string dotted(const std::string& prefix, const std::string& key);

// The layer-level and per-source keys STVL reads in that ROS version (ROS 2's layer list includes nav2's
// `plugin`; ROS 1's includes obstacle_range, found by searchParam, and both filter (noetic) and voxel_filter
// (melodic)).
const std::vector<std::string>& layer_keys(RosFlavour flavour);
const std::vector<std::string>& source_keys(RosFlavour flavour);

// The enclosing costmap's keys into out (resolution, robot_radius, width, height, rolling_window, update_frequency,
// track_unknown_space, footprint): nav2's ros__parameters, or ROS 1's costmap namespace, then the root.
void read_costmap(const LayerNodes& nodes, const std::string& file, RosStvlLayer& out);

// A costmap's `footprint`: "[[x, y], ...]" (nav2's and costmap_2d's string form) or a YAML list; "[]" is no
// footprint (nullopt). Throws through costmap.fail() for a malformed one.
std::optional<std::vector<Eigen::Vector2d>> read_footprint(YamlMap& costmap);

struct ReadLayer {
  RosStvlLayer layer;
  LayerNodes nodes;
};
// load_ros_stvl_layer(), except that with allow_negative_decay a voxel_decay < 0 is returned as read (lint
// reports it) instead of thrown.
ReadLayer read_layer(const std::string& path, const std::string& layer, const std::string& costmap,
                     bool allow_negative_decay);

}  // namespace stvl::config::ros_detail

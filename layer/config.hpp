#pragma once
// A layer's config: which layer (map.layer_type), STVL's map keys, nav2's layer keys, nav2's master costmap around
// it, and the sensors that feed it. Plain structs; config/ reads them from a scenario or a nav2 parameter file.
#include <string>
#include <vector>

#include "layer/nav2_costmap.hpp"
#include "layer/nav2_observation_buffer.hpp"
#include "layer/nav2_obstacle_layer.hpp"
#include "layer/observation.hpp"
#include "mapping/config.hpp"

namespace stvl::layer {

// YAML map.layer_type (with a ROS parameter file, the layer's `plugin`): STVL's layer
// (spatio_temporal_voxel_layer/SpatioTemporalVoxelLayer), nav2's nav2_costmap_2d::VoxelLayer or ObstacleLayer.
enum class LayerType { kStvl, kNav2Voxel, kNav2Obstacle };
LayerType parse_layer_type(const std::string& text);  // "stvl" | "nav2_voxel" | "nav2_obstacle"; throws
std::string to_string(LayerType type);

// The obstacle layer's marking range rule (nav2_obstacle_layer.hpp): "pre_5697" (kWorld3d, before #5697), "5697"
// (kCells) or "6092" (kCellsAndWorld2d, nav2 today); throws std::invalid_argument.
nav2::MarkingRange parse_nav2_marking_range(const std::string& text);
std::string to_string(nav2::MarkingRange rule);

// nav2's layer keys (YAML map.nav2_layer.<key>, or the plugin's own keys in a nav2 parameter file), with the defaults
// VoxelLayer::onInitialize and ObstacleLayer::onInitialize declare (jazzy f4108e5 = main a3a9704).
struct Nav2LayerParams {
  int z_voxels = 10;                       // z_voxels: levels of a column, 1..16 (VoxelLayer)
  double z_resolution_m = 0.2;             // z_resolution (VoxelLayer)
  double origin_z_m = 0.0;                 // origin_z (VoxelLayer)
  int unknown_threshold = 15;              // unknown_threshold; VoxelLayer adds 16 - z_voxels
  int mark_threshold = 0;                  // mark_threshold: a column marks its cell with more marked voxels than this
  double min_obstacle_height_m = 0.0;      // min_obstacle_height: the layer's own band on marking (both layers)
  double max_obstacle_height_m = 2.0;      // max_obstacle_height
  int combination_method = 1;              // combination_method: 0 overwrite, 1 max, 2 max without unknown overwrite
  bool footprint_clearing_enabled = true;  // footprint_clearing_enabled
  bool publish_voxel_map = false;          // publish_voxel_map: the voxel grid goes into bags as nav2 publishes it
  // The obstacle layer's marking range rule (nav2_marking_range); the voxel layer's is always the 3D squared one.
  nav2::MarkingRange marking_range = nav2::MarkingRange::kCellsAndWorld2d;  // nav2_marking_range
  nav2::PurgeRule purge_rule = nav2::PurgeRule::kJazzy;  // nav2_purge_rule: jazzy | main (out-of-order stamps only)
  void validate() const;                                 // throws std::invalid_argument naming the key
};

struct LayerConfig {
  LayerType type = LayerType::kStvl;
  mapping::StvlConfig map;  // YAML map: STVL's layer keys and the bench's switches (voxel_size is nav2's resolution)
  Nav2LayerParams nav2;     // YAML map.nav2_layer: nav2's layer keys (nav2 layer types only)
  // nav2's master costmap around the layer (YAML map.nav2_costmap); off unless its width and height are given. A nav2
  // layer always lives in one: without it, a rolling window 2 * (its farthest range) + 1 m wide.
  Nav2CostmapConfig nav2_costmap;
  std::vector<SensorConfig> sensors;  // at least one; each with at least one source
};

}  // namespace stvl::layer

#pragma once
// An STVL layer read from a ROS parameter file as users keep it: a nav2 params file (ROS 2), a move_base
// costmap file (ROS 1) or a bare layer mapping. Defaults are STVL's own, per ROS version (ros2 branch for ROS 2
// and bare files, noetic-devel for ROS 1, which melodic-devel matches but for voxel_filter); keys STVL does not
// read are accepted here and reported by lint_ros_stvl_layer(). Lengths in metres, angles in radians, times in
// seconds.
#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

#include "mapping/config.hpp"

namespace stvl::config {

// kRos2: `ros__parameters` above the layer; kRos1: `plugins: [{name, type}]`; kBare: the layer mapping alone
// (read by ROS 2's rules).
enum class RosFlavour { kRos2, kRos1, kBare };
// STVL's `filter` ("passthrough", "voxel", anything else none); ROS 1 melodic's `voxel_filter: true` is kVoxel;
// a ROS 2 file's "passthrough_relative" and "voxel_relative" are kPassthrough and kVoxel with filter_relative.
enum class RosSourceFilter { kNone, kPassthrough, kVoxel };

// One entry of observation_sources.
struct RosObservationSource {
  std::string name;                                            // e.g. "pointcloud"
  int line = 0;                                                // 1-based line of its mapping's key
  std::string data_type = "PointCloud2", topic, sensor_frame;  // topic defaults to the name in ROS 1, "" in ROS 2
  // obstacle_range defaults to 2.5 m in ROS 2, 3.0 m in ROS 1; expected_update_rate and observation_persistence
  // are read into it too (the pipeline's source buffers apply them)
  mapping::ObservationSource stvl;
  int model_type = 0;                                      // 0 depth camera, 1 STVL's 3D lidar model (stvl.model)
  RosSourceFilter filter = RosSourceFilter::kPassthrough;  // STVL's default in every version
  std::string filter_text = "passthrough";  // `filter` as written (lint names a string STVL does not know)
  // passthrough_relative / voxel_relative (ROS 2 files: the ros2 branch's relative filters, PR #304 as 22f7927):
  // filter is kPassthrough / kVoxel, applied in z_reference_frame (STVL's default: the costmap's global frame).
  bool filter_relative = false;
  std::string z_reference_frame;
  int voxel_min_points = 0;
  bool clear_after_reading = false, inf_is_valid = false, enabled = true;
};

struct RosStvlLayer {
  std::string file, layer_name, costmap_name;  // costmap_name "" for a bare file or a ROS 1 file's root
  RosFlavour flavour = RosFlavour::kRos2;
  mapping::StvlConfig map;     // voxel_size, voxel_decay, decay_model, mark_threshold
  int decay_model_code = 0;    // as written: 0 linear, 1 exponential, any other persistent
  int combination_method = 1;  // 0 overwrite, 1 max
  bool update_footprint_enabled = true;
  bool track_unknown_space = false;  // STVL's default is the costmap's track_unknown_space
  bool mapping_mode = false, publish_voxel_map = false, enabled = true;
  double map_save_duration_s = 60.0, transform_tolerance_s = 0.2;
  // The enclosing costmap's keys; absent when the file does not write them.
  std::optional<double> resolution_m, robot_radius_m, width_m, height_m;
  std::optional<bool> rolling_window;
  bool costmap_track_unknown_space = false;   // the costmap's own (nav2's master default: NO_INFORMATION or FREE)
  std::optional<double> update_frequency_hz;  // nav2's / costmap_2d's update_frequency (STVL updates at it)
  std::optional<std::vector<Eigen::Vector2d>> footprint;  // "[[x, y], ...]" or a YAML list, in base_link
  std::vector<RosObservationSource> sources;
};

// `layer`: the layer's name ("stvl_layer"); "" picks the only STVL layer in the file. `costmap`:
// "local_costmap", "global_costmap", or "" for the only costmap holding that layer. Throws
// std::invalid_argument "file:line: dotted.key: message" for malformed YAML, a missing layer (naming those
// there), a layer whose plugin is not STVL, a source without a mapping, wrong types, values STVL or
// mapping::*::validate() reject (voxel_decay < 0, STVL's default, included), and sources that are not depth
// cameras (model_type 1, LaserScan).
RosStvlLayer load_ros_stvl_layer(const std::string& path, const std::string& layer, const std::string& costmap = "");

}  // namespace stvl::config

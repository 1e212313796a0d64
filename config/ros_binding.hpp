#pragma once
// An STVL layer read from a ROS parameter file, bound to a scenario's cameras: the layer's map parameters, each
// enabled observation source as a source of the camera its topic or sensor_frame names, and the decimation its
// `filter` asks for.
#include <string>
#include <vector>

#include "config/ros_lint.hpp"
#include "config/ros_params.hpp"
#include "pipeline/pipeline.hpp"

namespace stvl::config {

// The camera a source belongs to: the camera whose name is the topic's first segment ("/front/depth/points",
// "front/points") or the sensor_frame itself or its prefix before '_' ("front_depth_optical_frame",
// "front_link"); the longest such name wins, the topic before the frame. -1 when none.
int bound_camera_index(const RosObservationSource& source, const std::vector<pipeline::CameraConfig>& cameras);

// Replaces config.map's STVL parameters (voxel_size, voxel_decay, decay_model, mark_threshold) and every
// camera's sources with the layer's; when `derive_filter`, config.filter follows the sources' common
// `filter` (passthrough: the marking band only; voxel: a voxel grid at the layer's voxel_size with
// voxel_min_points ignored as STVL's PCL ignores it, then the band; none: neither). Throws std::invalid_argument
// "file:line: key: ..." for a source bound to no camera, a camera left without a source, and sources whose filters
// differ.
void apply_ros_layer(const RosStvlLayer& layer, pipeline::PipelineConfig& config, bool derive_filter);

// Each bound source's camera (name, FOV, mount, range), for lint_ros_stvl_layer().
std::vector<BoundCamera> bound_cameras(const pipeline::PipelineConfig& config);

}  // namespace stvl::config

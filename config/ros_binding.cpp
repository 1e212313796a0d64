#include "config/ros_binding.hpp"

#include "mapping/footprint.hpp"
#include "recording/bag_writer.hpp"

#include <algorithm>
#include <stdexcept>

namespace stvl::config {
namespace {

std::string where(const RosStvlLayer& layer, const RosObservationSource& source) {
  return layer.file + ":" + std::to_string(source.line) + ": " +
         (layer.layer_name.empty() ? source.name : layer.layer_name + "." + source.name) + ": ";
}

bool topic_names(const std::string& topic, const std::string& camera) {
  const std::string t = !topic.empty() && topic.front() == '/' ? topic.substr(1) : topic;
  return t == camera || t.rfind(camera + "/", 0) == 0;
}

bool frame_names(const std::string& frame, const std::string& camera) {
  return frame == camera || frame.rfind(camera + "_", 0) == 0;
}

std::string filter_name(const RosObservationSource& source) {
  const char* relative = source.filter_relative ? "_relative" : "";
  switch (source.filter) {
    case RosSourceFilter::kNone: return "none";
    case RosSourceFilter::kPassthrough: return std::string("passthrough") + relative;
    case RosSourceFilter::kVoxel: return std::string("voxel") + relative;
  }
  return "?";
}

// The frame a relative filter's band is in: STVL's default (empty here) and the global frames are the world's
// z; base_link the robot's. Other frames are not simulated.
mapping::ZReference z_reference_of(const RosStvlLayer& layer, const RosObservationSource& source) {
  const std::string& frame = source.z_reference_frame;
  if (frame.empty() || frame == "map" || frame == "odom" || frame == "world") return mapping::ZReference::kGlobal;
  if (frame == recording::kBaseFrame) return mapping::ZReference::kBaseLink;
  throw std::invalid_argument(where(layer, source) + "z_reference_frame '" + frame + "': the bench's frames for a " +
                              "height band are the global frame (map, odom) and " + recording::kBaseFrame +
                              " (the robot's base on the floor); write one of them");
}

}  // namespace

int bound_camera_index(const RosObservationSource& source, const std::vector<pipeline::CameraConfig>& cameras) {
  // The camera with the longest name that `names(value, name)` accepts; -1 when none does.
  const auto longest = [&](const std::string& value, bool (*names)(const std::string&, const std::string&)) {
    int best = -1;
    for (std::size_t i = 0; i < cameras.size(); ++i)
      if (names(value, cameras[i].name) && (best < 0 || cameras[i].name.size() > cameras[best].name.size()))
        best = static_cast<int>(i);
    return best;
  };
  const int by_topic = longest(source.topic, topic_names);
  return by_topic >= 0 ? by_topic : longest(source.sensor_frame, frame_names);
}

namespace {

// The layer's map settings, STVL's footprint clearing with the costmap's footprint (nav2: a non-empty footprint
// wins over robot_radius) and nav2's master costmap around the layer.
void apply_map_settings(const RosStvlLayer& layer, pipeline::PipelineConfig& config) {
  config.map.voxel_size_m = layer.map.voxel_size_m;
  config.map.voxel_decay_s = layer.map.voxel_decay_s;
  config.map.decay_model = layer.map.decay_model;
  config.map.mark_threshold = layer.map.mark_threshold;
  if (layer.update_frequency_hz) config.map.update_frequency_hz = *layer.update_frequency_hz;
  config.map.update_footprint_enabled = layer.update_footprint_enabled;
  config.tf.transform_tolerance_s = layer.transform_tolerance_s;  // the message filter's wait (cameras with timing)
  config.map.footprint_B.clear();
  if (layer.footprint && !layer.footprint->empty()) config.map.footprint_B = *layer.footprint;
  else if (layer.robot_radius_m) config.map.footprint_B = mapping::footprint_from_radius(*layer.robot_radius_m);
  // nav2's master costmap around the layer, when the file gives the costmap's size (nav2's defaults otherwise:
  // resolution 0.05, rolling_window false); a combination STVL does not do leaves it unmodelled.
  if (layer.width_m && layer.height_m && *layer.width_m > 0.0 && *layer.height_m > 0.0 &&
      (layer.combination_method == 0 || layer.combination_method == 1)) {
    layer::Nav2CostmapConfig& n = config.nav2_costmap;
    n.width_m = *layer.width_m;
    n.height_m = *layer.height_m;
    n.resolution_m = layer.resolution_m.value_or(0.05);
    n.rolling_window = layer.rolling_window.value_or(false);
    n.combination_method = layer.combination_method;
    n.track_unknown_space = layer.costmap_track_unknown_space;
    n.validate();
  }
}

// Binds each enabled observation source to its camera (replacing the cameras' sources); every camera needs one
// and all decimate with one filter. Returns the first enabled source (nullptr when none is).
const RosObservationSource* bind_sources(const RosStvlLayer& layer, std::vector<pipeline::CameraConfig>& cameras) {
  std::string names;
  for (const auto& c : cameras) names += (names.empty() ? "" : ", ") + c.name;
  for (auto& c : cameras) c.sources.clear();
  const RosObservationSource* first = nullptr;
  for (const auto& source : layer.sources) {
    if (!source.enabled) continue;  // STVL leaves a disabled source's buffer out of marking and clearing
    const int index = bound_camera_index(source, cameras);
    if (index < 0)
      throw std::invalid_argument(where(layer, source) + "bound to no camera: topic '" + source.topic +
                                  "' and sensor_frame '" + source.sensor_frame + "' name none of the cameras (" +
                                  names + "); write the topic as /<camera>/depth/points or the frame as " +
                                  "<camera>_depth_optical_frame");
    if (first && (source.filter != first->filter || source.filter_relative != first->filter_relative))
      throw std::invalid_argument(where(layer, source) + "filter " + filter_name(source) + " differs from " +
                                  first->name + "'s " + filter_name(*first) +
                                  "; the bench decimates every frame with one filter");
    if (!first) first = &source;
    cameras[index].sources.push_back({source.name, source.stvl});
    // STVL's buffer with filter none transforms the cloud and filters nothing: no height band.
    cameras[index].sources.back().params.height_band = source.filter != RosSourceFilter::kNone;
    // The ros2 branch's relative filters band (and decimate) in z_reference_frame.
    if (source.filter_relative) cameras[index].sources.back().params.z_reference = z_reference_of(layer, source);
    // The clearing volume is built in sensor_frame: the camera's link when it names it, else the cloud's frame.
    if (source.sensor_frame == recording::camera_link_frame(cameras[index].name))
      cameras[index].sources.back().params.sensor_frame = mapping::SensorFrame::kLink;
  }
  for (const auto& c : cameras)
    if (c.sources.empty())
      throw std::invalid_argument(layer.file + ": " + layer.layer_name +
                                  ": no enabled observation source is bound to camera '" + c.name +
                                  "' (bind one through its topic /" + c.name + "/... or its sensor_frame)");
  return first;
}

// The bench's filter from the first source's: STVL's height band and, with filter voxel, its VoxelGrid.
void derive_filter_from(const RosStvlLayer& layer, const RosObservationSource& first,
                        pipeline::PipelineConfig& config) {
  filter::FilterConfig& f = config.filter;
  const layer::HeightBand band = pipeline::marking_band(config);
  f.passthrough = {band.min_m, band.max_m};
  f.passthrough_enabled = first.filter != RosSourceFilter::kNone;
  f.type = first.filter == RosSourceFilter::kVoxel ? filter::FilterType::kVoxel : filter::FilterType::kNone;
  f.voxel.voxel_size_m = layer.map.voxel_size_m;
  // STVL's VoxelGrid takes the band as its z filter limits, before the leaves are counted.
  f.band_before_decimation = first.filter == RosSourceFilter::kVoxel;
  // voxel_min_points (STVL #241): VoxelGrid<PCLPointCloud2> ignored it before PCL 1.12 (PCL commit 7a7210dd), so
  // on ROS 1 Noetic (Ubuntu 20.04, PCL 1.10) every leaf counts; ROS 2 Humble and later (PCL >= 1.12) drop leaves
  // with fewer points. A ROS 2 file is read as Humble or later (Foxy and Galactic, on PCL 1.10, behave like ROS 1).
  f.voxel.min_points_per_voxel = layer.flavour == RosFlavour::kRos1 ? 1 : std::max(1, first.voxel_min_points);
}

}  // namespace

void apply_ros_layer(const RosStvlLayer& layer, pipeline::PipelineConfig& config, bool derive_filter) {
  apply_map_settings(layer, config);
  const RosObservationSource* first = bind_sources(layer, config.cameras);
  if (derive_filter && first) derive_filter_from(layer, *first, config);
}

std::vector<BoundCamera> bound_cameras(const pipeline::PipelineConfig& config) {
  std::vector<BoundCamera> bound;
  for (const auto& c : config.cameras)
    for (const auto& source : c.sources)
      bound.push_back({source.name, c.intrinsics.hfov_rad(), c.intrinsics.vfov_rad(), c.name, c.mount.height_m,
                       c.mount.pitch_rad, c.mount.roll_rad, c.intrinsics.max_range_m});
  return bound;
}

}  // namespace stvl::config

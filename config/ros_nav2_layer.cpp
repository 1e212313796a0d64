#include "config/ros_nav2_layer.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "common/enum_names.hpp"
#include "common/format.hpp"
#include "config/ros_binding.hpp"
#include "config/ros_params_detail.hpp"
#include "config/yaml_reader.hpp"
#include "mapping/footprint.hpp"

namespace stvl::config {
namespace {

using ros_detail::dotted;
using ros_detail::key_line;
using ros_detail::LayerNodes;

// The keys VoxelLayer::onInitialize (and the ObstacleLayer's it calls) and ObstacleLayer::onInitialize declare for
// the plugin and for each source (navigation2 jazzy f4108e5, plugins/voxel_layer.cpp and obstacle_layer.cpp), and
// nav2's `plugin` itself.
const std::vector<std::string> kObstacleLayerKeys = {"plugin",
                                                     "enabled",
                                                     "footprint_clearing_enabled",
                                                     "min_obstacle_height",
                                                     "max_obstacle_height",
                                                     "combination_method",
                                                     "observation_sources",
                                                     "tf_filter_tolerance"};
const std::vector<std::string> kVoxelOnlyKeys = {"z_voxels",          "origin_z",       "z_resolution",
                                                 "unknown_threshold", "mark_threshold", "publish_voxel_map"};
const std::vector<std::string> kSourceKeys = {"topic",
                                              "sensor_frame",
                                              "observation_persistence",
                                              "expected_update_rate",
                                              "data_type",
                                              "min_obstacle_height",
                                              "max_obstacle_height",
                                              "inf_is_valid",
                                              "marking",
                                              "clearing",
                                              "transport_type",
                                              "obstacle_max_range",
                                              "obstacle_min_range",
                                              "raytrace_max_range",
                                              "raytrace_min_range"};

std::vector<std::string> layer_keys_of(layer::LayerType type) {
  std::vector<std::string> keys = kObstacleLayerKeys;
  if (type == layer::LayerType::kNav2Voxel) keys.insert(keys.end(), kVoxelOnlyKeys.begin(), kVoxelOnlyKeys.end());
  return keys;
}

std::vector<std::string> split_words(const std::string& text) {
  std::istringstream in(text);  // as ObstacleLayer does: `while (ss >> source)`
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

// One source with ObstacleLayer::onInitialize's defaults.
RosNav2Source read_source(const LayerNodes& nodes, const std::string& name, const std::string& file, int sources_line) {
  const YAML::Node node = nodes.layer[name];
  const std::string path = dotted(nodes.layer_path, name);
  if (!node || !node.IsMap()) {
    std::ostringstream text;
    text << file << ":" << sources_line << ": " << dotted(nodes.layer_path, "observation_sources") << ": source '"
         << name << "' has no mapping " << path;
    throw std::invalid_argument(text.str());
  }
  YamlMap m(node, file, path);
  RosNav2Source s;
  s.name = s.topic = name;  // nav2: the topic defaults to the source's name
  s.line = key_line(nodes.layer, name);
  s.source.name = name;
  mapping::ObservationSource& p = s.source.params;
  layer::Nav2SourceRanges& r = s.source.nav2;
  p.marking = true, p.clearing = false;
  p.min_obstacle_height_m = 0.0, p.max_obstacle_height_m = 0.0;  // nav2's source defaults: nothing above the floor
  m.get("topic", s.topic);
  m.get("sensor_frame", s.sensor_frame);
  m.get("observation_persistence", p.observation_persistence_s);
  m.get("expected_update_rate", p.expected_update_rate_s);
  m.get("data_type", s.data_type);
  m.get("min_obstacle_height", p.min_obstacle_height_m);
  m.get("max_obstacle_height", p.max_obstacle_height_m);
  m.get("inf_is_valid", r.inf_is_valid);
  m.get("marking", p.marking);
  m.get("clearing", p.clearing);
  m.get("obstacle_max_range", r.obstacle_max_range_m);
  m.get("obstacle_min_range", r.obstacle_min_range_m);
  m.get("raytrace_max_range", r.raytrace_max_range_m);
  m.get("raytrace_min_range", r.raytrace_min_range_m);
  if (s.data_type == "LaserScan")
    m.fail(m.raw("data_type"), "data_type",
           "LaserScan is not simulated: only PointCloud2 sources (the depth cameras' clouds) run here");
  if (s.data_type != "PointCloud2")
    m.fail(m.raw("data_type"), "data_type",
           "'" + s.data_type + "': nav2 reads only PointCloud2 or LaserScan (and throws at startup)");
  const std::pair<const char*, double> ranges[] = {
      {"obstacle_max_range", r.obstacle_max_range_m},           {"obstacle_min_range", r.obstacle_min_range_m},
      {"raytrace_max_range", r.raytrace_max_range_m},           {"raytrace_min_range", r.raytrace_min_range_m},
      {"observation_persistence", p.observation_persistence_s}, {"expected_update_rate", p.expected_update_rate_s}};
  for (const auto& [key, value] : ranges)
    if (!(std::isfinite(value) && value >= 0.0)) m.fail(m.raw(key), key, general(value) + ": must be finite and >= 0");
  for (const char* key : {"min_obstacle_height", "max_obstacle_height"}) {
    const double value = std::string(key) == "min_obstacle_height" ? p.min_obstacle_height_m : p.max_obstacle_height_m;
    if (!std::isfinite(value)) m.fail(m.raw(key), key, "must be finite");
  }
  return s;
}

// The located layer and the file's root, read.
struct Located {
  YAML::Node root;
  LayerNodes nodes;
};

Located locate(const std::string& path, const std::string& layer, const std::string& costmap) {
  Located l{load_yaml_file(path), {}};
  l.nodes = ros_detail::locate_layer(l.root, path, layer, costmap, false);
  return l;
}

void add(std::vector<LintFinding>& out, const std::string& file, int line, const std::string& key,
         const std::string& what, const std::string& instead) {
  out.push_back({file, line, key, what, instead});
}

}  // namespace

bool ros_layer_is_nav2(const std::string& path, const std::string& layer, const std::string& costmap) {
  return ros_detail::is_nav2_layer(locate(path, layer, costmap).nodes.plugin);
}

RosNav2Layer load_ros_nav2_layer(const std::string& path, const std::string& layer, const std::string& costmap) {
  const Located located = locate(path, layer, costmap);
  const LayerNodes& nodes = located.nodes;
  if (!ros_detail::is_nav2_layer(nodes.plugin))
    throw std::invalid_argument(path + ": " + nodes.layer_path + ": plugin '" + nodes.plugin +
                                "' is not nav2's VoxelLayer or ObstacleLayer");
  if (nodes.flavour != RosFlavour::kRos2)
    throw std::invalid_argument(path + ": " + nodes.layer_path + ": nav2's layers are read from nav2 (ROS 2) files");
  RosNav2Layer out;
  out.file = path, out.layer_name = nodes.layer_name, out.costmap_name = nodes.costmap_name, out.plugin = nodes.plugin;
  out.type =
      nodes.plugin == ros_detail::kNav2VoxelPlugin ? layer::LayerType::kNav2Voxel : layer::LayerType::kNav2Obstacle;

  // The costmap's keys, Costmap2DROS's defaults where absent.
  RosStvlLayer costmap_keys;
  ros_detail::read_costmap(nodes, path, costmap_keys);
  out.width_m = costmap_keys.width_m.value_or(5.0);
  out.height_m = costmap_keys.height_m.value_or(5.0);
  out.resolution_m = costmap_keys.resolution_m.value_or(0.1);
  out.rolling_window = costmap_keys.rolling_window.value_or(false);
  out.update_frequency_hz = costmap_keys.update_frequency_hz.value_or(5.0);
  out.track_unknown_space = costmap_keys.costmap_track_unknown_space;
  if (costmap_keys.footprint && !costmap_keys.footprint->empty()) {
    out.footprint_B = *costmap_keys.footprint;
    out.footprint_source = "footprint";
  } else {
    out.footprint_B = mapping::footprint_from_radius(costmap_keys.robot_radius_m.value_or(0.1));
    out.footprint_source = costmap_keys.robot_radius_m ? "robot_radius" : "nav2's default robot_radius 0.1";
  }
  YamlMap costmap_map(nodes.costmap, path, nodes.costmap_path);
  if (!(std::isfinite(out.resolution_m) && out.resolution_m > 0.0))
    costmap_map.fail(costmap_map.raw("resolution"), "resolution", general(out.resolution_m) + ": must be > 0 m");
  if (!(out.width_m > 0.0 && out.height_m > 0.0))
    costmap_map.fail(costmap_map.raw("width"), "width", "width and height must be > 0 m");

  // The plugin's keys (VoxelLayer's and ObstacleLayer's defaults are Nav2LayerParams').
  YamlMap m(nodes.layer, path, nodes.layer_path);
  layer::Nav2LayerParams& p = out.params;
  m.get("enabled", out.enabled);
  m.get("footprint_clearing_enabled", p.footprint_clearing_enabled);
  m.get("min_obstacle_height", p.min_obstacle_height_m);
  m.get("max_obstacle_height", p.max_obstacle_height_m);
  m.get("combination_method", p.combination_method);
  if (out.type == layer::LayerType::kNav2Voxel) {
    m.get("z_voxels", p.z_voxels);
    m.get("origin_z", p.origin_z_m);
    m.get("z_resolution", p.z_resolution_m);
    m.get("unknown_threshold", p.unknown_threshold);
    m.get("mark_threshold", p.mark_threshold);
    m.get("publish_voxel_map", p.publish_voxel_map);
  }
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();  // "nav2_layer.<key> = ..."
    const std::string key =
        message.substr(std::string("nav2_layer.").size(), message.find(' ') - std::string("nav2_layer.").size());
    m.fail(m.raw(key), key, message.substr(message.find('=') + 2));
  }
  if (!out.enabled)
    m.fail(m.raw("enabled"), "enabled", "false: the layer marks and clears nothing; nothing to simulate");
  std::string sources;
  m.get("observation_sources", sources);
  const int sources_line = std::max(1, key_line(nodes.layer, "observation_sources"));
  for (const auto& name : split_words(sources)) out.sources.push_back(read_source(nodes, name, path, sources_line));
  if (out.sources.empty())
    m.fail(m.raw("observation_sources"), "observation_sources", "names no source: the layer reads no sensor");
  return out;
}

void apply_ros_nav2_layer(const RosNav2Layer& layer, pipeline::PipelineConfig& config) {
  config.layer_type = layer.type;
  config.nav2_layer = layer.params;
  config.map.voxel_size_m = layer.resolution_m;
  config.map.update_frequency_hz = layer.update_frequency_hz;
  config.map.footprint_B = layer.footprint_B;
  config.map.validate();
  layer::Nav2CostmapConfig& n = config.nav2_costmap;
  n.width_m = layer.width_m;
  n.height_m = layer.height_m;
  n.resolution_m = layer.resolution_m;
  n.rolling_window = layer.rolling_window;
  n.track_unknown_space = layer.track_unknown_space;
  std::string names;
  for (const auto& c : config.cameras) names += (names.empty() ? "" : ", ") + c.name;
  for (auto& c : config.cameras) c.sources.clear();
  for (const RosNav2Source& s : layer.sources) {
    RosObservationSource as_stvl;  // the binding rule is the one STVL's sources follow
    as_stvl.topic = s.topic;
    as_stvl.sensor_frame = s.sensor_frame;
    const int index = bound_camera_index(as_stvl, config.cameras);
    if (index < 0)
      throw std::invalid_argument(layer.file + ":" + std::to_string(s.line) + ": " + dotted(layer.layer_name, s.name) +
                                  ": bound to no camera: topic '" + s.topic + "' and sensor_frame '" + s.sensor_frame +
                                  "' name none of the cameras (" + names +
                                  "); write the topic as /<camera>/depth/points");
    config.cameras[index].sources.push_back(s.source);
  }
  for (const auto& c : config.cameras)
    if (c.sources.empty())
      throw std::invalid_argument(layer.file + ": " + layer.layer_name +
                                  ": no observation source is bound to camera '" + c.name +
                                  "' (bind one through its topic /" + c.name + "/...)");
}

std::vector<LintFinding> lint_ros_nav2_layer(const std::string& path, const std::string& layer_name,
                                             const std::string& costmap) {
  const Located located = locate(path, layer_name, costmap);
  const LayerNodes& nodes = located.nodes;
  const RosNav2Layer layer = load_ros_nav2_layer(path, layer_name, costmap);
  std::vector<LintFinding> out;
  const auto unknown = [&](const YAML::Node& map, const std::string& prefix, const std::vector<std::string>& known,
                           const std::vector<std::string>& sources) {
    for (const auto& entry : map) {
      const std::string k = entry.first.Scalar();
      if (std::find(known.begin(), known.end(), k) != known.end()) continue;
      if (std::find(sources.begin(), sources.end(), k) != sources.end()) continue;  // a source's mapping
      const std::string nearest = nearest_name(k, known);
      add(out, path, key_line(map, k), dotted(prefix, k), "nav2's " + layer.plugin + " does not read it",
          nearest.empty() ? "remove it" : nearest + " (the nearest key it reads)");
    }
  };
  std::vector<std::string> source_names;
  for (const auto& s : layer.sources) source_names.push_back(s.name);
  unknown(nodes.layer, nodes.layer_path, layer_keys_of(layer.type), source_names);
  const layer::Nav2LayerParams& p = layer.params;
  const double top_m = p.origin_z_m + p.z_voxels * p.z_resolution_m;
  const int layer_line = std::max(1, nodes.layer_line);
  if (layer.type == layer::LayerType::kNav2Voxel && top_m < p.max_obstacle_height_m)
    add(out, path, std::max(layer_line, key_line(nodes.layer, "z_voxels")), dotted(nodes.layer_path, "z_voxels"),
        "origin_z + z_voxels * z_resolution = " + general(top_m) + " m, under max_obstacle_height " +
            general(p.max_obstacle_height_m) + " m: nothing between is marked (nav2 starts anyway)",
        "z_resolution: " + general((p.max_obstacle_height_m - p.origin_z_m) / p.z_voxels) + " (or a lower band)");
  for (const RosNav2Source& s : layer.sources) {
    const YAML::Node node = nodes.layer[s.name];
    const std::string prefix = dotted(nodes.layer_path, s.name);
    unknown(node, prefix, kSourceKeys, {});
    const layer::Nav2SourceRanges& r = s.source.nav2;
    const mapping::ObservationSource& q = s.source.params;
    if (q.marking && q.clearing && r.raytrace_max_range_m < r.obstacle_max_range_m)
      add(out, path, std::max(s.line, key_line(node, "raytrace_max_range")), dotted(prefix, "raytrace_max_range"),
          "raytrace_max_range " + general(r.raytrace_max_range_m) + " m < obstacle_max_range " +
              general(r.obstacle_max_range_m) + " m: obstacles marked beyond it are never cleared (nav2 starts anyway)",
          "raytrace_max_range: " + general(r.obstacle_max_range_m + 0.5));
    if (!(q.max_obstacle_height_m > q.min_obstacle_height_m))
      add(out, path, std::max(s.line, key_line(node, "max_obstacle_height")), dotted(prefix, "max_obstacle_height"),
          (key_line(node, "max_obstacle_height") ? std::string("") : "absent, so nav2's default ") +
              general(q.max_obstacle_height_m) + " m: the buffer keeps no point above " +
              general(q.min_obstacle_height_m) + " m, the source marks and clears nothing (nav2 starts anyway)",
          "max_obstacle_height: " + general(p.max_obstacle_height_m));
    if (layer.type == layer::LayerType::kNav2Voxel && q.marking && top_m < q.max_obstacle_height_m &&
        !(top_m < p.max_obstacle_height_m))
      add(out, path, std::max(s.line, key_line(node, "max_obstacle_height")), dotted(prefix, "max_obstacle_height"),
          "the voxel grid ends at " + general(top_m) + " m: points up to " + general(q.max_obstacle_height_m) +
              " m are kept but not marked above it",
          "z_resolution or z_voxels covering the band");
    const double half_window_m = std::min(layer.width_m, layer.height_m) / 2.0;
    if (q.marking && layer.rolling_window && r.obstacle_max_range_m > half_window_m)
      add(out, path, std::max(s.line, key_line(node, "obstacle_max_range")), dotted(prefix, "obstacle_max_range"),
          general(r.obstacle_max_range_m) + " m reaches past the rolling window's half width " +
              general(half_window_m) +
              " m: obstacles seen farther ahead are marked off the grid or rolled out "
              "of it (nav2 starts anyway)",
          "width and height: " + general(2.0 * r.obstacle_max_range_m) +
              " (or obstacle_max_range: " + general(half_window_m) + ")");
    if (r.inf_is_valid)
      add(out, path, std::max(s.line, key_line(node, "inf_is_valid")), dotted(prefix, "inf_is_valid"),
          "no effect on a PointCloud2 source (nav2 reads it for LaserScan only)", "remove it");
  }
  std::sort(out.begin(), out.end(), [](const LintFinding& a, const LintFinding& b) { return a.line < b.line; });
  return out;
}

}  // namespace stvl::config

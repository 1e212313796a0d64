#include "config/ros_params.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "config/ros_params_detail.hpp"
#include "config/stvl_keys.hpp"
#include "config/yaml_reader.hpp"

namespace stvl::config {
namespace ros_detail {
namespace {

[[noreturn]] void fail_at(const std::string& file, int line, const std::string& key, const std::string& message) {
  std::ostringstream text;
  text << file << ":" << line << ": " << key << ": " << message;
  throw std::invalid_argument(text.str());
}

// Runs a mapping::*::validate() and names the line of the key its message starts with ("max_z = ...").
template <typename Config>
void validate_at(const Config& config, YamlMap& map) {
  try {
    config.validate();
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    map.fail(YAML::Node(), message.substr(0, message.find(' ')), message);
  }
}

// STVL's filter string; relative: the ros2 branch's *_relative variants (PR #304, 22f7927), which noetic lacks.
RosSourceFilter filter_of(const std::string& text, bool ros2, bool& relative) {
  relative = ros2 && (text == "passthrough_relative" || text == "voxel_relative");
  if (text == "passthrough" || (relative && text == "passthrough_relative")) return RosSourceFilter::kPassthrough;
  if (text == "voxel" || (relative && text == "voxel_relative")) return RosSourceFilter::kVoxel;
  return RosSourceFilter::kNone;  // STVL: "No filters activated." for anything else
}

// ROS 1 reads obstacle_range with searchParam(): the source, then the layer, then the namespaces above it.
void read_ros1_obstacle_range(const LayerNodes& nodes, YamlMap& source, YamlMap& layer, const std::string& file,
                              double& range_m) {
  range_m = 3.0;  // noetic-devel / melodic-devel default
  if (source.has("obstacle_range")) return source.get("obstacle_range", range_m);
  if (layer.has("obstacle_range")) return layer.get("obstacle_range", range_m);
  for (std::size_t i = 0; i < nodes.search_chain.size(); ++i) {
    YamlMap scope(nodes.search_chain[i], file, i == 0 ? nodes.costmap_path : "");
    if (scope.has("obstacle_range")) return scope.get("obstacle_range", range_m);
  }
}

RosObservationSource read_source(const LayerNodes& nodes, YamlMap& layer, const std::string& name,
                                 const std::string& file, int sources_line) {
  const YAML::Node node = nodes.layer[name];
  const std::string path = dotted(nodes.layer_path, name);
  if (!node || !node.IsMap())
    fail_at(file, sources_line, dotted(nodes.layer_path, "observation_sources"),
            "source '" + name + "' has no mapping " + path);
  YamlMap m(node, file, path);
  RosObservationSource s;
  s.name = name;
  s.line = key_line(nodes.layer, name);
  const bool ros1 = nodes.flavour == RosFlavour::kRos1;
  if (ros1) s.topic = name;  // ROS 1's default topic is the source's name
  m.get("data_type", s.data_type);
  m.get("topic", s.topic);
  m.get("sensor_frame", s.sensor_frame);
  // Every number and flag of the source from the one table; ROS 1 finds obstacle_range with searchParam().
  read_source_keys(m, s.stvl, ros1 ? kReadByNoetic : kReadByRos2, {"obstacle_range"});
  if (ros1) read_ros1_obstacle_range(nodes, m, layer, file, s.stvl.obstacle_range_m);
  else m.get("obstacle_range", s.stvl.obstacle_range_m);
  m.get("model_type", s.model_type);
  m.get("voxel_min_points", s.voxel_min_points);
  m.get("clear_after_reading", s.clear_after_reading);
  m.get("inf_is_valid", s.inf_is_valid);
  m.get("enabled", s.enabled);
  std::string filter = "passthrough";
  if (!ros1 || m.has("filter")) {
    m.get("filter", filter);  // ROS 2 and noetic-devel
    s.filter = filter_of(filter, !ros1, s.filter_relative);
    s.filter_text = filter;
    if (!ros1) m.get("z_reference_frame", s.z_reference_frame);
  } else {
    bool voxel_filter = false;  // melodic-devel: false is the passthrough filter
    m.get("voxel_filter", voxel_filter);
    s.filter = voxel_filter ? RosSourceFilter::kVoxel : RosSourceFilter::kPassthrough;
  }

  if (s.data_type == "LaserScan")
    m.fail(YAML::Node(), "data_type", "LaserScan: only depth cameras (PointCloud2) are simulated");
  if (s.data_type != "PointCloud2")
    m.fail(YAML::Node(), "data_type", "'" + s.data_type + "': STVL reads only PointCloud2 or LaserScan");
  if (s.model_type != 0 && s.model_type != 1)
    m.fail(YAML::Node(), "model_type", std::to_string(s.model_type) + ": STVL knows 0 (depth camera) and 1 (3D lidar)");
  s.stvl.model = static_cast<mapping::ClearingModel>(s.model_type);
  if (s.voxel_min_points < 0) m.fail(YAML::Node(), "voxel_min_points", "must be >= 0");
  validate_at(s.stvl, m);
  return s;
}

std::vector<std::string> split_words(const std::string& text) {
  std::istringstream in(text);  // as STVL does: `while (ss >> source)`
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

}  // namespace

std::optional<std::vector<Eigen::Vector2d>> read_footprint(YamlMap& costmap) {
  YAML::Node node = costmap.raw("footprint");
  if (!node) return std::nullopt;
  if (node.IsScalar()) {
    try {
      node = YAML::Load(node.Scalar());
    } catch (const YAML::Exception&) {
      costmap.fail(YAML::Node(), "footprint", "expected \"[[x, y], ...]\", got '" + node.Scalar() + "'");
    }
  }
  std::vector<std::vector<double>> points;
  try {
    points = node.as<std::vector<std::vector<double>>>();
  } catch (const YAML::Exception&) {
    costmap.fail(YAML::Node(), "footprint", "expected a list of [x, y] points");
  }
  if (points.empty()) return std::nullopt;
  if (points.size() < 3) costmap.fail(YAML::Node(), "footprint", "needs at least three points");
  std::vector<Eigen::Vector2d> footprint;
  for (const auto& p : points) {
    if (p.size() != 2) costmap.fail(YAML::Node(), "footprint", "each point must be [x, y]");
    if (!std::isfinite(p[0]) || !std::isfinite(p[1])) costmap.fail(YAML::Node(), "footprint", "points must be finite");
    footprint.emplace_back(p[0], p[1]);
  }
  return footprint;
}

// The costmap's own keys: nav2's ros__parameters; ROS 1's costmap namespace, then the file's root.
void read_costmap(const LayerNodes& nodes, const std::string& file, RosStvlLayer& out) {
  std::vector<YamlMap> scopes;
  if (nodes.flavour == RosFlavour::kRos2) scopes.emplace_back(nodes.costmap, file, nodes.costmap_path);
  for (std::size_t i = 0; i < nodes.search_chain.size(); ++i)
    scopes.emplace_back(nodes.search_chain[i], file, i == 0 ? nodes.costmap_path : "");
  const auto optional_of = [&](const std::string& key, auto& value) {
    for (auto& scope : scopes)
      if (scope.has(key)) {
        typename std::decay_t<decltype(value)>::value_type v{};
        scope.get(key, v);
        value = v;
        return;
      }
  };
  optional_of("resolution", out.resolution_m);
  optional_of("robot_radius", out.robot_radius_m);
  if (out.robot_radius_m && !(std::isfinite(*out.robot_radius_m) && *out.robot_radius_m > 0.0))
    for (auto& scope : scopes)
      if (scope.has("robot_radius")) scope.fail(scope.raw("robot_radius"), "robot_radius", "must be finite and > 0 m");
  optional_of("width", out.width_m);
  optional_of("height", out.height_m);
  optional_of("rolling_window", out.rolling_window);
  optional_of("update_frequency", out.update_frequency_hz);
  std::optional<bool> tracking;
  optional_of("track_unknown_space", tracking);
  out.track_unknown_space = tracking.value_or(false);  // STVL's default follows the costmap's (false)
  out.costmap_track_unknown_space = out.track_unknown_space;
  for (auto& scope : scopes)
    if (scope.has("footprint")) {
      out.footprint = read_footprint(scope);
      break;
    }
}

ReadLayer read_layer(const std::string& path, const std::string& layer, const std::string& costmap,
                     bool allow_negative_decay) {
  const YAML::Node root = load_yaml_file(path);
  ReadLayer result{RosStvlLayer{}, locate_layer(root, path, layer, costmap)};
  const LayerNodes& nodes = result.nodes;
  RosStvlLayer& out = result.layer;
  out.file = path;
  out.layer_name = nodes.layer_name;
  out.costmap_name = nodes.costmap_name;
  out.flavour = nodes.flavour;
  read_costmap(nodes, path, out);

  YamlMap m(nodes.layer, path, nodes.layer_path);
  out.map.voxel_decay_s = -1.0;  // STVL's default in every version
  m.get("voxel_size", out.map.voxel_size_m);
  m.get("voxel_decay", out.map.voxel_decay_s);
  m.get("decay_model", out.decay_model_code);
  out.map.decay_model = out.decay_model_code == 0   ? mapping::DecayModel::kLinear
                        : out.decay_model_code == 1 ? mapping::DecayModel::kExponential
                                                    : mapping::DecayModel::kPersistent;  // STVL: every other code
  m.get("mark_threshold", out.map.mark_threshold);
  m.get("combination_method", out.combination_method);
  m.get("update_footprint_enabled", out.update_footprint_enabled);
  m.get("track_unknown_space", out.track_unknown_space);
  m.get("mapping_mode", out.mapping_mode);
  m.get("publish_voxel_map", out.publish_voxel_map);
  m.get("enabled", out.enabled);
  m.get("map_save_duration", out.map_save_duration_s);
  m.get("transform_tolerance", out.transform_tolerance_s);
  std::string sources;
  m.get("observation_sources", sources);

  if (out.map.voxel_decay_s < 0.0 && !allow_negative_decay) {
    const int line = m.has("voxel_decay") ? key_line(nodes.layer, "voxel_decay") : nodes.layer_line;
    std::ostringstream what;
    what << (m.has("voxel_decay") ? "" : "absent, so STVL's default ") << out.map.voxel_decay_s
         << " s: STVL removes every voxel at the next update, before it builds the costmap, so the layer never "
            "marks a cell; the bench's map needs voxel_decay >= 0 (write e.g. voxel_decay: 15.0, STVL's example)";
    fail_at(path, line, dotted(nodes.layer_path, "voxel_decay"), what.str());
  }
  mapping::StvlConfig checked = out.map;
  checked.voxel_decay_s = std::max(checked.voxel_decay_s, 0.0);  // lint reports a negative one itself
  validate_at(checked, m);
  const int sources_line = std::max(1, key_line(nodes.layer, "observation_sources"));
  for (const auto& name : split_words(sources)) out.sources.push_back(read_source(nodes, m, name, path, sources_line));
  if (out.sources.empty())
    fail_at(path, sources_line, dotted(nodes.layer_path, "observation_sources"),
            "names no source: STVL reads no sensor");
  return result;
}

}  // namespace ros_detail

RosStvlLayer load_ros_stvl_layer(const std::string& path, const std::string& layer, const std::string& costmap) {
  return ros_detail::read_layer(path, layer, costmap, false).layer;
}

}  // namespace stvl::config

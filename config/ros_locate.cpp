// Where the STVL layer sits in a ROS parameter file (nav2, move_base or bare), and the keys STVL reads.
#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "config/ros_params_detail.hpp"
#include "config/stvl_keys.hpp"

namespace stvl::config::ros_detail {
namespace {

constexpr int kMaxDepth = 4;  // nav2: node namespace, node name, ros__parameters, layer

// One layer named in a costmap's plugin list (or a bare layer mapping).
struct Candidate {
  LayerNodes nodes;
  std::string plugin;      // pluginlib type as written
  int line = 1;            // line of its entry in the plugin list (of its mapping when bare)
  std::string plugin_key;  // dotted key of the plugin type, for messages
  int plugins_line = 1;    // the costmap's plugin list
  std::string plugins_key;
};

int line_of(const YAML::Node& node) { return node.Mark().is_null() ? 1 : node.Mark().line + 1; }

[[noreturn]] void fail(const std::string& file, int line, const std::string& key, const std::string& message) {
  std::ostringstream text;
  text << file << ":" << line << ": " << (key.empty() ? "document" : key) << ": " << message;
  throw std::invalid_argument(text.str());
}

std::string scalar(const YAML::Node& node) { return node && node.IsScalar() ? node.Scalar() : std::string(); }
bool is_stvl(const std::string& plugin) { return plugin == kStvlPlugin || plugin == kStvlClass; }

}  // namespace

bool is_nav2_layer(const std::string& plugin) { return plugin == kNav2VoxelPlugin || plugin == kNav2ObstaclePlugin; }

namespace {

// nav2: `<node>: ros__parameters: {plugins: [names], <name>: {plugin: type}}` (Foxy: plugin_names/plugin_types).
void add_ros2_costmap(const YAML::Node& params, const std::string& costmap, const std::string& file,
                      std::vector<Candidate>& out) {
  const bool foxy = !params["plugins"] && params["plugin_names"];
  const YAML::Node names = params[foxy ? "plugin_names" : "plugins"];
  const YAML::Node types = params["plugin_types"];
  if (!names || !names.IsSequence()) return;  // another node of the stack
  const std::string list_key = dotted(costmap, foxy ? "plugin_names" : "plugins");
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (!names[i].IsScalar()) fail(file, line_of(names[i]), list_key, "expected a list of layer names");
    Candidate c;
    c.nodes.flavour = RosFlavour::kRos2;
    c.nodes.layer_name = c.nodes.layer_path = names[i].Scalar();
    c.nodes.costmap_name = c.nodes.costmap_path = costmap;
    c.nodes.costmap = params;
    // A layer listed but not configured (nav2 runs it with its defaults) has no mapping: params[] gives an invalid
    // node then, which yaml-cpp refuses to assign.
    if (const YAML::Node layer = params[c.nodes.layer_name]; layer.IsDefined()) c.nodes.layer.reset(layer);
    c.nodes.layer_line = std::max(1, key_line(params, c.nodes.layer_name));
    c.line = line_of(names[i]);
    c.plugins_line = key_line(params, foxy ? "plugin_names" : "plugins");
    c.plugins_key = list_key;
    if (c.nodes.layer && c.nodes.layer.IsMap() && c.nodes.layer["plugin"]) {
      c.plugin = scalar(c.nodes.layer["plugin"]);
      c.line = key_line(c.nodes.layer, "plugin");
      c.plugin_key = dotted(c.nodes.layer_path, "plugin");
    } else if (foxy && types && types.IsSequence() && i < types.size()) {
      c.plugin = scalar(types[i]);
      c.plugin_key = dotted(costmap, "plugin_types");
    }
    out.push_back(c);
  }
}

// move_base: `plugins: [{name: x, type: t}]`, the layer a mapping beside the list or at the root.
void add_ros1_costmap(const YAML::Node& costmap_node, const std::string& costmap, const YAML::Node& root,
                      std::vector<Candidate>& out) {
  const YAML::Node plugins = costmap_node["plugins"];
  for (std::size_t i = 0; i < plugins.size(); ++i) {
    const YAML::Node entry = plugins[i];
    Candidate c;
    c.nodes.flavour = RosFlavour::kRos1;
    c.nodes.layer_name = c.nodes.layer_path = scalar(entry["name"]);
    c.nodes.costmap_name = c.nodes.costmap_path = costmap;
    c.nodes.costmap = costmap_node;
    c.nodes.search_chain = {costmap_node};
    if (!costmap_node.is(root)) c.nodes.search_chain.push_back(root);
    for (const auto& scope : c.nodes.search_chain)
      if (scope[c.nodes.layer_name] && scope[c.nodes.layer_name].IsMap()) {
        c.nodes.layer = scope[c.nodes.layer_name];
        c.nodes.layer_line = key_line(scope, c.nodes.layer_name);
        break;
      }
    c.plugin = scalar(entry["type"]);
    c.line = line_of(entry);
    c.plugins_key = dotted(costmap, "plugins");
    c.plugin_key = c.plugins_key + "[" + std::to_string(i) + "].type";
    c.plugins_line = key_line(costmap_node, "plugins");
    out.push_back(c);
  }
}

bool is_ros1_plugin_list(const YAML::Node& node) {
  if (!node || !node.IsSequence() || node.size() == 0) return false;
  for (const auto& entry : node)
    if (!entry.IsMap() || !entry["name"] || !entry["type"]) return false;
  return true;
}

void walk(const YAML::Node& map, const std::string& key, int depth, const YAML::Node& root, const std::string& file,
          bool& ros2, std::vector<Candidate>& ros2_out, std::vector<Candidate>& ros1_out) {
  if (is_ros1_plugin_list(map["plugins"])) add_ros1_costmap(map, key, root, ros1_out);
  if (depth >= kMaxDepth) return;
  for (const auto& entry : map) {
    if (!entry.second.IsMap()) continue;
    const std::string child = scalar(entry.first);
    if (child == "ros__parameters") {
      ros2 = true;
      add_ros2_costmap(entry.second, key, file, ros2_out);
    } else {
      walk(entry.second, child, depth + 1, root, file, ros2, ros2_out, ros1_out);
    }
  }
}

// The file is the layer (has observation_sources), or its top-level mappings are layers.
std::vector<Candidate> bare_candidates(const YAML::Node& root, const std::string& layer) {
  std::vector<Candidate> out;
  const auto add = [&](const YAML::Node& node, const std::string& name, int line) {
    Candidate c;
    c.nodes.flavour = RosFlavour::kBare;
    c.nodes.layer = node;
    c.nodes.layer_name = c.nodes.layer_path = name;
    c.nodes.layer_line = line;
    c.plugin = kStvlPlugin;
    c.line = line;
    out.push_back(c);
  };
  if (root["observation_sources"]) {
    add(root, layer, 1);
    out.back().nodes.layer_path = "";  // the file's own keys
    return out;
  }
  for (const auto& entry : root)
    if (entry.second.IsMap() && entry.second["observation_sources"])
      add(entry.second, scalar(entry.first), line_of(entry.first));
  return out;
}

std::string describe(const std::vector<Candidate>& candidates) {
  std::string text;
  for (const auto& c : candidates) {
    text += (text.empty() ? "" : ", ") + c.nodes.layer_name;
    if (!c.nodes.costmap_name.empty()) text += " in " + c.nodes.costmap_name;
    text += " (" + (c.plugin.empty() ? std::string("no plugin") : c.plugin) + ")";
  }
  return text.empty() ? "none" : text;
}

}  // namespace

int key_line(const YAML::Node& map, const std::string& key) {
  if (!map || !map.IsMap()) return 0;
  for (const auto& entry : map)
    if (entry.first.IsScalar() && entry.first.Scalar() == key) return line_of(entry.first);
  return 0;
}

std::string dotted(const std::string& prefix, const std::string& key) {
  return prefix.empty() ? key : prefix + "." + key;
}

LayerNodes locate_layer(const YAML::Node& root, const std::string& file, const std::string& layer,
                        const std::string& costmap, bool stvl_only) {
  const auto runs = [&](const std::string& plugin) { return is_stvl(plugin) || (!stvl_only && is_nav2_layer(plugin)); };
  if (!root.IsMap()) fail(file, line_of(root), "", "expected a mapping of keys to values");
  bool ros2 = false;
  std::vector<Candidate> ros2_found, ros1_found;
  walk(root, "", 0, root, file, ros2, ros2_found, ros1_found);
  std::vector<Candidate> all = ros2 ? ros2_found : ros1_found;
  if (!ros2 && all.empty()) all = bare_candidates(root, layer);
  if (all.empty()) fail(file, 1, "", "no costmap plugin list (plugins) and no layer mapping (observation_sources)");

  std::vector<Candidate> in_costmap;
  for (const auto& c : all)
    if (costmap.empty() || c.nodes.costmap_name == costmap) in_costmap.push_back(c);
  if (in_costmap.empty()) fail(file, 1, costmap, "no costmap of that name (layers: " + describe(all) + ")");
  const Candidate& first = in_costmap.front();

  std::vector<Candidate> chosen;
  for (const auto& c : in_costmap)
    if (layer.empty()
            ? runs(c.plugin)
            : (c.nodes.layer_name == layer || (c.nodes.flavour == RosFlavour::kBare && c.nodes.layer_name.empty())))
      chosen.push_back(c);
  const std::string what = stvl_only ? "STVL layer" : "3D layer (STVL, nav2's VoxelLayer or ObstacleLayer)";
  if (chosen.empty()) {
    bool nav2_layer = false;  // a layer the bench runs, but not where only STVL's is read
    for (const auto& c : in_costmap) nav2_layer = nav2_layer || is_nav2_layer(c.plugin);
    fail(
        file, first.plugins_line, first.plugins_key,
        (layer.empty() ? "no " + what : "no layer '" + layer + "'") + " (layers: " + describe(in_costmap) + ")" +
            (layer.empty() && nav2_layer && stvl_only ? "; nav2's VoxelLayer and ObstacleLayer run in `stvl-bench run` "
                                                        "(map.ros_params), not here: only " +
                                                            std::string(kStvlPlugin)
                                                      : std::string()));
  }
  if (chosen.size() > 1)
    fail(file, chosen[1].line, chosen[1].nodes.layer_path,
         (layer.empty() ? "several " + what + "s" : "layer '" + layer + "' is in several costmaps") + " (" +
             describe(chosen) + "); name the " + (layer.empty() ? "layer" : "costmap"));
  const Candidate& c = chosen.front();
  if (!runs(c.plugin))
    fail(file, c.line, c.plugin_key.empty() ? dotted(c.nodes.layer_path, "plugin") : c.plugin_key,
         (c.plugin.empty() ? std::string("no plugin type") : "plugin is '" + c.plugin + "'") + ", not " + kStvlPlugin +
             (stvl_only ? std::string() : std::string(", ") + kNav2VoxelPlugin + " or " + kNav2ObstaclePlugin));
  if (!c.nodes.layer || !c.nodes.layer.IsMap())
    fail(file, c.line, c.nodes.layer_path, "listed in " + c.plugins_key + " but has no mapping of parameters");
  LayerNodes nodes = c.nodes;
  nodes.plugin = c.plugin;
  return nodes;
}

// From the one table (config/stvl_keys.hpp): the keys that ROS version of STVL reads.
unsigned readers_of(RosFlavour flavour) {
  return flavour == RosFlavour::kRos1 ? kReadByNoetic | kReadByMelodic : kReadByRos2;
}

const std::vector<std::string>& layer_keys(RosFlavour flavour) {
  static const std::vector<std::string> ros2 = stvl_key_names(StvlScope::kLayer, kReadByRos2);
  static const std::vector<std::string> ros1 = stvl_key_names(StvlScope::kLayer, readers_of(RosFlavour::kRos1));
  return flavour == RosFlavour::kRos1 ? ros1 : ros2;
}

const std::vector<std::string>& source_keys(RosFlavour flavour) {
  static const std::vector<std::string> ros2 = stvl_key_names(StvlScope::kSource, kReadByRos2);
  static const std::vector<std::string> ros1 = stvl_key_names(StvlScope::kSource, readers_of(RosFlavour::kRos1));
  return flavour == RosFlavour::kRos1 ? ros1 : ros2;
}

}  // namespace stvl::config::ros_detail

// nav2's servers from a nav2 parameter file (ros_navigation.hpp). Plugin names and parameter names as navigation2
// jazzy f4108e5 declares them (nav2_controller/src/controller_server.cpp, nav2_planner/src/planner_server.cpp,
// nav2_costmap_2d/src/costmap_2d_ros.cpp, nav2_costmap_2d/plugins/inflation_layer.cpp, nav2_behaviors/
// include/nav2_behaviors/timed_behavior.hpp, nav2_bt_navigator).
#include "config/ros_navigation.hpp"

#include <cmath>
#include <optional>

#include "config/ros_params_detail.hpp"
#include "config/yaml_reader.hpp"

namespace stvl::config {
namespace {

// nav2's plugin names, new style (::) and the old pluginlib style (/) both accepted.
bool is_plugin(const std::string& written, const std::string& package, const std::string& cls) {
  return written == package + "::" + cls || written == package + "/" + cls;
}

// `name.ros__parameters` at the root (or `name.name.ros__parameters`, the costmaps' layout); a node that is not a
// mapping when absent (test with IsMap(): a default YAML::Node is defined).
YAML::Node parameters(const YAML::Node& root, const std::string& name, std::string& path) {
  for (const bool nested : {false, true}) {
    YAML::Node node = root[name];
    if (nested && node && node.IsMap()) node.reset(node[name]);  // reset: `=` would write into the document
    if (node && node.IsMap() && node["ros__parameters"] && node["ros__parameters"].IsMap()) {
      path = nested ? name + "." + name + ".ros__parameters" : name + ".ros__parameters";
      return node["ros__parameters"];
    }
  }
  return YAML::Node();
}

void get(YamlMap& m, const char* key, double& value) {
  if (!m.has(key)) return;
  m.get(key, value);
  if (!std::isfinite(value)) m.fail(m.raw(key), key, "must be finite");
}

LintFinding finding(const YamlMap& m, const std::string& key, const std::string& what, const std::string& instead) {
  LintFinding f;
  f.file = m.file();
  const std::string where = m.where(key);  // "file:line: key"
  const std::size_t colon = where.find(':', f.file.size());
  if (colon != std::string::npos) f.line = std::atoi(where.c_str() + colon + 1);
  f.key = m.location(key);
  f.what_stvl_does = what;
  f.write_instead = instead;
  return f;
}

// The plugin list `list_key` names; its first entry's mapping and plugin, or nothing.
bool first_plugin(YamlMap& server, const YAML::Node& node, const char* list_key, std::string& name,
                  std::string& plugin) {
  std::vector<std::string> names;
  if (server.has(list_key)) server.get(list_key, names);
  if (names.empty()) return false;
  name = names.front();
  const YAML::Node entry = node[name];
  plugin = entry && entry.IsMap() && entry["plugin"] ? entry["plugin"].as<std::string>("") : "";
  return true;
}

void read_controller(const YAML::Node& root, const std::string& file, navigation::NavigationConfig& c,
                     std::vector<LintFinding>& out) {
  std::string path;
  const YAML::Node node = parameters(root, "controller_server", path);
  if (!node.IsMap()) return;
  YamlMap server(node, file, path);
  get(server, "controller_frequency", c.controller_frequency_hz);
  get(server, "failure_tolerance", c.failure_tolerance_s);
  get(server, "costmap_update_timeout", c.controller_costmap_timeout_s);
  std::string name, plugin;
  if (first_plugin(server, node, "goal_checker_plugins", name, plugin)) {
    YamlMap g = server.map(name);
    if (is_plugin(plugin, "nav2_controller", "SimpleGoalChecker")) {
      get(g, "xy_goal_tolerance", c.goal_checker.xy_goal_tolerance);
      get(g, "yaw_goal_tolerance", c.goal_checker.yaw_goal_tolerance);
      if (g.has("stateful")) g.get("stateful", c.goal_checker.stateful);
    } else {
      out.push_back(finding(g, "plugin", "goal checker '" + plugin + "' is not modelled",
                            "nav2_controller::SimpleGoalChecker with its defaults stands in"));
    }
  }
  if (first_plugin(server, node, "progress_checker_plugins", name, plugin)) {
    YamlMap p = server.map(name);
    if (is_plugin(plugin, "nav2_controller", "SimpleProgressChecker")) {
      get(p, "required_movement_radius", c.progress_checker.required_movement_radius);
      get(p, "movement_time_allowance", c.progress_checker.movement_time_allowance);
    } else {
      out.push_back(finding(p, "plugin", "progress checker '" + plugin + "' is not modelled",
                            "nav2_controller::SimpleProgressChecker with its defaults stands in"));
    }
  }
  if (first_plugin(server, node, "controller_plugins", name, plugin)) {
    YamlMap f = server.map(name);
    if (is_plugin(plugin, "nav2_regulated_pure_pursuit_controller", "RegulatedPurePursuitController")) {
      for (const auto& [key, value] : navigation::rpp_double_keys(c.controller)) get(f, key, *value);
      for (const auto& [key, value] : navigation::rpp_bool_keys(c.controller))
        if (f.has(key)) f.get(key, *value);
    } else {
      out.push_back(finding(f, "plugin", "controller '" + plugin + "' is not modelled",
                            "Regulated Pure Pursuit (nav2_regulated_pure_pursuit_controller) with its defaults "
                            "stands in"));
    }
  }
}

void read_planner(const YAML::Node& root, const std::string& file, navigation::NavigationConfig& c,
                  std::vector<LintFinding>& out) {
  std::string path;
  const YAML::Node node = parameters(root, "planner_server", path);
  if (!node.IsMap()) return;
  YamlMap server(node, file, path);
  get(server, "costmap_update_timeout", c.planner_costmap_timeout_s);
  std::string name, plugin;
  if (!first_plugin(server, node, "planner_plugins", name, plugin)) return;
  YamlMap p = server.map(name);
  if (is_plugin(plugin, "nav2_navfn_planner", "NavfnPlanner")) {
    get(p, "tolerance", c.planner.tolerance_m);
    if (p.has("use_astar")) p.get("use_astar", c.planner.use_astar);
    if (p.has("allow_unknown")) p.get("allow_unknown", c.planner.allow_unknown);
  } else {
    out.push_back(finding(p, "plugin", "planner '" + plugin + "' is not modelled",
                          "NavFn (nav2_navfn_planner) with its defaults stands in"));
  }
}

// footprint_read: whether a costmap read before gave the footprint (the global one's then stays unread).
void read_costmap(const YAML::Node& root, const std::string& file, const std::string& name,
                  navigation::NavigationConfig& c, navigation::CostmapParams& m, bool& footprint_read,
                  std::vector<LintFinding>& out) {
  std::string path;
  const YAML::Node node = parameters(root, name, path);
  if (!node.IsMap()) return;
  YamlMap costmap(node, file, path);
  get(costmap, "width", m.width_m);
  get(costmap, "height", m.height_m);
  get(costmap, "resolution", m.resolution_m);
  get(costmap, "update_frequency", m.update_frequency_hz);
  get(costmap, "publish_frequency", m.publish_frequency_hz);
  if (costmap.has("rolling_window")) costmap.get("rolling_window", m.rolling_window);
  if (costmap.has("track_unknown_space")) costmap.get("track_unknown_space", m.track_unknown_space);
  // The robot's footprint: the local costmap's (the controller's and behaviours'); the global one's if only it has.
  const bool footprint_keys = costmap.has("footprint") || costmap.has("robot_radius");
  if (footprint_keys && (name == "local_costmap" || !footprint_read)) {
    footprint_read = true;
    std::optional<std::vector<Eigen::Vector2d>> footprint;
    if (costmap.has("footprint")) footprint = ros_detail::read_footprint(costmap);
    if (footprint) {
      c.footprint_m = *footprint;  // nav2: a footprint wins over robot_radius
    } else if (costmap.has("robot_radius")) {
      get(costmap, "robot_radius", c.robot_radius_m);
      c.footprint_m.clear();
    }
    get(costmap, "footprint_padding", c.footprint_padding_m);
  }
  std::vector<std::string> plugins;
  if (costmap.has("plugins")) costmap.get("plugins", plugins);
  bool inflation = false;
  for (const auto& layer : plugins) {
    const YAML::Node entry = node[layer];
    const std::string plugin = entry && entry.IsMap() && entry["plugin"] ? entry["plugin"].as<std::string>("") : "";
    if (!is_plugin(plugin, "nav2_costmap_2d", "InflationLayer")) continue;
    inflation = true;
    YamlMap i = costmap.map(layer);
    get(i, "inflation_radius", m.inflation.inflation_radius_m);
    get(i, "cost_scaling_factor", m.inflation.cost_scaling_factor);
    if (i.has("inflate_unknown")) i.get("inflate_unknown", m.inflation.inflate_unknown);
    if (i.has("inflate_around_unknown")) i.get("inflate_around_unknown", m.inflation.inflate_around_unknown);
  }
  if (!plugins.empty() && !inflation)
    out.push_back(finding(costmap, "plugins", name + " has no nav2_costmap_2d::InflationLayer",
                          "nav2's inflation with its defaults is applied all the same"));
}

void read_behaviors(const YAML::Node& root, const std::string& file, navigation::NavigationConfig& c) {
  std::string path;
  const YAML::Node node = parameters(root, "behavior_server", path);
  if (!node.IsMap()) return;
  YamlMap b(node, file, path);
  get(b, "cycle_frequency", c.behaviors.cycle_frequency_hz);
  get(b, "simulate_ahead_time", c.behaviors.simulate_ahead_time_s);
  get(b, "max_rotational_vel", c.behaviors.max_rotational_vel);
  get(b, "min_rotational_vel", c.behaviors.min_rotational_vel);
  get(b, "rotational_acc_lim", c.behaviors.rotational_acc_lim);
}

void read_bt(const YAML::Node& root, const std::string& file, std::vector<LintFinding>& out) {
  std::string path;
  const YAML::Node node = parameters(root, "bt_navigator", path);
  if (!node.IsMap()) return;
  YamlMap bt(node, file, path);
  for (const char* key : {"default_nav_to_pose_bt_xml", "default_bt_xml_filename"}) {
    if (!bt.has(key)) continue;
    std::string xml;
    bt.get(key, xml);
    if (xml.empty() || xml.find("navigate_to_pose_w_replanning_and_recovery.xml") != std::string::npos) continue;
    out.push_back(finding(bt, key, "behaviour tree '" + xml + "' is not modelled",
                          "navigate_to_pose_w_replanning_and_recovery.xml (nav2's default) stands in"));
  }
}

}  // namespace

std::vector<LintFinding> read_ros_navigation(const std::string& path, navigation::NavigationConfig& c) {
  const YAML::Node root = load_yaml_file(path);
  std::string unused;
  bool any = false;
  for (const char* server :
       {"controller_server", "planner_server", "local_costmap", "global_costmap", "behavior_server", "bt_navigator"})
    any = any || parameters(root, server, unused).IsMap();
  if (!any)
    throw std::invalid_argument(path +
                                ": no nav2 server in the file (controller_server, planner_server, local_costmap, "
                                "global_costmap, behavior_server or bt_navigator with ros__parameters)");
  std::vector<LintFinding> out;
  read_controller(root, path, c, out);
  read_planner(root, path, c, out);
  bool footprint_read = false;
  read_costmap(root, path, "local_costmap", c, c.local_costmap, footprint_read, out);
  read_costmap(root, path, "global_costmap", c, c.global_costmap, footprint_read, out);
  read_behaviors(root, path, c);
  read_bt(root, path, out);
  return out;
}

}  // namespace stvl::config

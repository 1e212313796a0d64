// A scenario's `navigation:` section (issue 41): the mode, the goal, and nav2's keys of the closed loop's servers
// (navigation/config.hpp), each named as nav2's parameter files name it; errors blame file, line and key.
#include <cmath>
#include <filesystem>
#include <limits>

#include "config/ros_navigation.hpp"
#include "config/scenario_detail.hpp"
#include "worldgen/map_world.hpp"
#include "worldgen/mjcf_writer.hpp"

namespace stvl::config::scenario_detail {
namespace {

using DoubleKeys = std::vector<std::pair<const char*, double*>>;
using BoolKeys = std::vector<std::pair<const char*, bool*>>;

void read_numbers(YamlMap& m, const DoubleKeys& doubles, const BoolKeys& bools = {}) {
  for (const auto& [key, value] : doubles) {
    m.get(key, *value);
    require_range(m, key, *value, std::isfinite(*value), "must be finite");
  }
  for (const auto& [key, value] : bools) m.get(key, *value);
}

// `radius_word`: how validate() names this costmap's inflation radius.
void read_costmap(YamlMap m, navigation::CostmapParams& c, bool rolling, const char* radius_word,
                  std::vector<Blame>& blame, std::vector<std::unique_ptr<YamlMap>>& keep) {
  if (rolling) read_numbers(m, {{"width", &c.width_m}, {"height", &c.height_m}});
  read_numbers(m,
               {{"resolution", &c.resolution_m},
                {"update_frequency", &c.update_frequency_hz},
                {"publish_frequency", &c.publish_frequency_hz}},
               {{"track_unknown_space", &c.track_unknown_space}});
  for (const auto& [key, value] : {std::pair<const char*, double>{"width", c.width_m},
                                   {"height", c.height_m},
                                   {"resolution", c.resolution_m},
                                   {"update_frequency", c.update_frequency_hz},
                                   {"publish_frequency", c.publish_frequency_hz}})
    if (rolling || (std::string(key) != "width" && std::string(key) != "height"))
      require_range(m, key, value, value > 0, "must be > 0");
  if (m.has("inflation_layer")) {
    keep.push_back(std::make_unique<YamlMap>(m.map("inflation_layer")));
    YamlMap& i = *keep.back();
    read_numbers(i,
                 {{"inflation_radius", &c.inflation.inflation_radius_m},
                  {"cost_scaling_factor", &c.inflation.cost_scaling_factor}},
                 {{"inflate_unknown", &c.inflation.inflate_unknown},
                  {"inflate_around_unknown", &c.inflation.inflate_around_unknown}});
    require_range(i, "cost_scaling_factor", c.inflation.cost_scaling_factor, c.inflation.cost_scaling_factor >= 0,
                  "must be >= 0");
    i.finish();
    blame.push_back({radius_word, &i, "inflation_radius"});
  }
  m.finish();
}

// A goal on a nav2 map must lie on one of its free cells: not outside it, not in a wall, not in unknown space (the
// world built from it has nothing there, but nav2's global costmap would be unknown). Names the nearest free cell.
void check_goal_on_map(YamlMap& n, const worldgen::MapWorld& world, const navigation::Pose2& goal) {
  const worldgen::OccupancyGrid& grid = world.grid;
  const Eigen::Vector2d p(goal.x_m, goal.y_m);
  const auto cell = grid.frame.cell_of(p);
  if (cell && grid.at(*cell) == worldgen::Cell::kFree) return;
  const char* where = !cell                                         ? "outside the nav2 map"
                      : grid.at(*cell) == worldgen::Cell::kOccupied ? "in an occupied cell of the nav2 map"
                                                                    : "in unknown space of the nav2 map";
  double best = std::numeric_limits<double>::infinity();
  Eigen::Vector2d nearest = p;
  for (std::size_t i = 0; i < grid.cells.size(); ++i) {
    if (grid.cells[i] != worldgen::Cell::kFree) continue;
    const Eigen::Vector2d c = grid.frame.cell_center_W(grid.frame.cell(i));
    if ((c - p).squaredNorm() < best) best = (c - p).squaredNorm(), nearest = c;
  }
  n.fail(n.has("goal") ? n.raw("goal") : YAML::Node(), "goal",
         "(" + fixed(p.x(), 2) + ", " + fixed(p.y(), 2) + ") m lies " + where + " (" + world.map_yaml +
             "); the nearest free cell is (" + fixed(nearest.x(), 2) + ", " + fixed(nearest.y(), 2) + ") m");
}

}  // namespace

bool navigation_closed_loop(YamlMap& root) {
  if (!root.has("navigation")) return false;
  YAML::Node node = root.raw("navigation");
  if (!node.IsMap() || !node["mode"]) return false;
  std::string mode;
  try {
    mode = node["mode"].as<std::string>();
  } catch (const YAML::Exception&) {
    return false;  // read_navigation() names the line and the type expected
  }
  try {
    return navigation::parse_navigation_mode(mode) == navigation::NavigationMode::kClosedLoop;
  } catch (const std::invalid_argument& e) {
    YamlMap(node, root.file(), "navigation").fail(node["mode"], "mode", e.what());
  }
}

void read_navigation(YamlMap n, Scenario& s, const std::vector<Eigen::Vector2d>& waypoints_W,
                     const std::string& base_dir, const worldgen::MapWorld* map_world) {
  navigation::NavigationConfig& c = s.navigation;
  std::string mode = "path";
  n.get("mode", mode);
  try {
    c.mode = navigation::parse_navigation_mode(mode);
  } catch (const std::invalid_argument& e) {
    n.fail(n.raw("mode"), "mode", e.what());
  }
  if (c.mode == navigation::NavigationMode::kPath) {
    n.finish();
    return;
  }
  // The goal: given, or the path's last waypoint facing along its last leg (a generated world's, a nav2 map's).
  std::vector<double> goal;
  n.get("goal", goal);
  if (!goal.empty()) {
    if (goal.size() != 3) n.fail(n.raw("goal"), "goal", "expected [x_m, y_m, yaw_deg]");
    require_range(n, "goal", "non-finite values", std::isfinite(goal[0] + goal[1] + goal[2]), "must be finite");
    c.goal = {goal[0], goal[1], goal[2] * kRadPerDeg};
  } else if (waypoints_W.size() >= 2) {
    const Eigen::Vector2d last = waypoints_W.back(), leg = last - waypoints_W[waypoints_W.size() - 2];
    c.goal = {last.x(), last.y(), std::atan2(leg.y(), leg.x())};
  } else {
    n.fail(YAML::Node(), "goal", "closed_loop needs a goal [x_m, y_m, yaw_deg] (or robot.waypoints to end at)");
  }
  if (map_world) {
    check_goal_on_map(n, *map_world, c.goal);
    // The global costmap's StaticLayer reads the map itself (nav2 ignores its origin yaw: a rotated map keeps the
    // building's bodies, rasterized, so that the static layer lies where the walls are).
    const worldgen::Nav2Map& m = map_world->map;
    if (m.meta.origin_yaw_rad == 0.0)
      c.static_map = navigation::OccupancyMap{
          m.width, m.height, m.meta.resolution_m, {m.meta.origin_x_m, m.meta.origin_y_m}, m.data};
  }
  // The footprint: navigation.robot_radius, else the nav2 parameter file's, else the scenario's (map.footprint,
  // map.robot_radius, map.ros_params, the URDF), else robot.xml's reach about base_link.
  std::vector<Blame> blame{{"navigation.mode", &n, "mode"}};  // first: blamed when no key is named
  std::vector<std::unique_ptr<YamlMap>> keep;
  c.robot_radius_m = std::numeric_limits<double>::quiet_NaN();  // unknown until a source below gives it
  if (!s.pipeline.map.footprint_B.empty()) c.footprint_m = s.pipeline.map.footprint_B;
  // The user's nav2 parameter file (navigation.ros_params, else map.ros_params when it holds nav2's servers): its
  // values over the defaults; the keys below over the file's.
  std::string ros_params;
  n.get("ros_params", ros_params);
  if (!ros_params.empty()) {
    ros_params = std::filesystem::path(ros_params).is_absolute()
                     ? ros_params
                     : (std::filesystem::path(base_dir) / ros_params).lexically_normal().string();
    try {
      s.navigation_findings = read_ros_navigation(ros_params, c);
    } catch (const std::invalid_argument& e) {
      n.fail(n.raw("ros_params"), "ros_params", e.what());
    }
    s.navigation_ros_params = ros_params;
  } else if (s.ros_params) {
    try {
      s.navigation_findings = read_ros_navigation(s.ros_params->path, c);
      s.navigation_ros_params = s.ros_params->path;
    } catch (const std::invalid_argument& e) {
      if (std::string(e.what()).find("no nav2 server") == std::string::npos) throw;  // a file of the layer alone
    }
  }
  if (n.has("robot_radius")) {  // over the scenario's and the file's footprint
    n.get("robot_radius", c.robot_radius_m);
    require_range(n, "robot_radius", c.robot_radius_m, std::isfinite(c.robot_radius_m) && c.robot_radius_m > 0,
                  "must be > 0 m");
    c.footprint_m.clear();
  }
  if (c.footprint_m.empty() && !std::isfinite(c.robot_radius_m)) {  // robot.xml's reach about base_link
    const std::filesystem::path dir = s.pipeline.world_xml.empty()
                                          ? std::filesystem::path(s.pipeline.world_path).parent_path()
                                          : std::filesystem::path(s.pipeline.world_include_dir);
    try {
      c.robot_radius_m = worldgen::robot_footprint_radius_m((dir / "robot.xml").string());
    } catch (const std::exception& e) {
      n.fail(YAML::Node(), "robot_radius", std::string("give it: the robot's reach could not be read: ") + e.what());
    }
  }
  read_numbers(n, {{"controller_frequency", &c.controller_frequency_hz},
                   {"failure_tolerance", &c.failure_tolerance_s},
                   {"replan_frequency", &c.replan_frequency_hz},
                   {"footprint_padding", &c.footprint_padding_m}});
  n.get("number_of_retries", c.number_of_retries);
  n.get("static_bodies", c.static_bodies);
  if (n.has("local_costmap"))
    read_costmap(n.map("local_costmap"), c.local_costmap, true,
                 "navigation.local_costmap.inflation_layer.inflation_radius", blame, keep);
  if (n.has("global_costmap"))
    read_costmap(n.map("global_costmap"), c.global_costmap, false,
                 "navigation.global_costmap.inflation_layer.inflation_radius", blame, keep);
  if (n.has("planner")) {
    keep.push_back(std::make_unique<YamlMap>(n.map("planner")));
    YamlMap& p = *keep.back();
    read_numbers(p, {{"tolerance", &c.planner.tolerance_m}},
                 {{"use_astar", &c.planner.use_astar}, {"allow_unknown", &c.planner.allow_unknown}});
    p.finish();
    validate_keys({{"tolerance", &p, "tolerance"}}, [&] { c.planner.validate(); });
  }
  if (n.has("controller")) {
    keep.push_back(std::make_unique<YamlMap>(n.map("controller")));
    YamlMap& r = *keep.back();
    navigation::RppParams& p = c.controller;
    const DoubleKeys doubles = navigation::rpp_double_keys(p);
    const BoolKeys bools = navigation::rpp_bool_keys(p);
    read_numbers(r, doubles, bools);
    r.finish();
    std::vector<Blame> rpp_blame;
    for (const auto& [key, value] : doubles) rpp_blame.push_back({key, &r, key});
    for (const auto& [key, value] : bools) rpp_blame.push_back({key, &r, key});
    validate_keys(rpp_blame, [&] { p.validate(); });
  }
  if (n.has("goal_checker")) {
    YamlMap g = n.map("goal_checker");
    read_numbers(g,
                 {{"xy_goal_tolerance", &c.goal_checker.xy_goal_tolerance},
                  {"yaw_goal_tolerance", &c.goal_checker.yaw_goal_tolerance}},
                 {{"stateful", &c.goal_checker.stateful}});
    for (const char* key : {"xy_goal_tolerance", "yaw_goal_tolerance"}) {
      double v = 0;
      g.get(key, v);
      require_range(g, key, v, v >= 0, "must be >= 0");
    }
    g.finish();
  }
  if (n.has("progress_checker")) {
    YamlMap g = n.map("progress_checker");
    read_numbers(g, {{"required_movement_radius", &c.progress_checker.required_movement_radius},
                     {"movement_time_allowance", &c.progress_checker.movement_time_allowance}});
    for (const char* key : {"required_movement_radius", "movement_time_allowance"}) {
      double v = 0;
      g.get(key, v);
      require_range(g, key, v, v >= 0, "must be >= 0");
    }
    g.finish();
  }
  if (n.has("behaviors")) {
    keep.push_back(std::make_unique<YamlMap>(n.map("behaviors")));
    YamlMap& b = *keep.back();
    navigation::BehaviorParams& p = c.behaviors;
    const DoubleKeys doubles{{"cycle_frequency", &p.cycle_frequency_hz},
                             {"simulate_ahead_time", &p.simulate_ahead_time_s},
                             {"max_rotational_vel", &p.max_rotational_vel},
                             {"min_rotational_vel", &p.min_rotational_vel},
                             {"rotational_acc_lim", &p.rotational_acc_lim},
                             {"time_allowance", &p.time_allowance_s},
                             {"spin_dist", &p.spin_dist_rad},
                             {"backup_dist", &p.backup_dist_m},
                             {"backup_speed", &p.backup_speed_mps},
                             {"wait_duration", &p.wait_duration_s}};
    read_numbers(b, doubles);
    b.finish();
    for (const auto& [key, value] : doubles) blame.push_back({key, &b, key});
  }
  for (const char* key :
       {"robot_radius", "controller_frequency", "failure_tolerance", "replan_frequency", "number_of_retries", "goal"})
    blame.push_back({key, &n, key});
  validate_keys(blame, [&] { c.validate(); });
  n.finish();
}

}  // namespace stvl::config::scenario_detail

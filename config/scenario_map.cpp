// A scenario's `nav2_map`: the world built in memory from a nav2 map (worldgen/map_world.hpp) and loaded
// through MuJoCo's virtual file system (nothing is written), and robot.waypoints planned on the map when the file
// leaves them out.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>

#include "config/scenario_detail.hpp"
#include "sim/urdf_robot.hpp"
#include "worldgen/map_world.hpp"
#include "worldgen/scenario_writer.hpp"

namespace stvl::config::scenario_detail {

std::shared_ptr<const worldgen::MapWorld> read_nav2_map(YamlMap map, Scenario& s, const std::string& base_dir) {
  std::string file;
  double wall_height_m = 2.5;
  map.require("file", file);
  require_range(map, "file", "an empty path", !file.empty(), "must not be empty");
  map.get("wall_height_m", wall_height_m);
  require_range(map, "wall_height_m", wall_height_m,
                std::isfinite(wall_height_m) && wall_height_m > 0 && wall_height_m <= 10, "must lie in (0, 10] m");
  map.finish();
  const std::string path = std::filesystem::path(file).is_absolute()
                               ? file
                               : (std::filesystem::path(base_dir) / file).lexically_normal().string();
  std::shared_ptr<worldgen::MapWorld> world;
  try {
    world = std::make_shared<worldgen::MapWorld>(worldgen::build_map_world(path, wall_height_m));
  } catch (const std::invalid_argument& e) {
    map.fail(map.raw("file"), "file", e.what());
  }
  s.pipeline.world_path = path;
  s.pipeline.world_xml = worldgen::write_mjcf(world->spec);
  s.pipeline.world_include_dir = std::filesystem::path(worldgen::shipped_robot_xml()).parent_path().string();
  return world;
}

namespace {

// The robot's footprint radius: the URDF robot's footprint (its collision shapes' hull) when it has one, else
// worlds/robot.xml's.
double robot_radius_m(const Scenario& s) {
  double radius_m = 0;
  if (s.pipeline.urdf_robot)
    for (const Eigen::Vector2d& corner : s.pipeline.urdf_robot->footprint_B)
      radius_m = std::max(radius_m, corner.norm());
  return radius_m > 0 ? radius_m : worldgen::robot_footprint_radius_m(worldgen::shipped_robot_xml());
}

}  // namespace

void plan_on_map(const worldgen::MapWorld& world, YamlMap& robot, Scenario& s) {
  const double radius_m = robot_radius_m(s);
  std::optional<Eigen::Vector2d> start;
  if (robot.has("start")) start = Eigen::Vector2d(s.pipeline.start_pose.x_m, s.pipeline.start_pose.y_m);
  worldgen::PlannedPath path;
  try {
    path = worldgen::plan_path(worldgen::map_drive_grid(world, radius_m), world.grid.cells, start, std::nullopt,
                               "robot.start", "the farthest point from it");
  } catch (const std::invalid_argument& e) {
    robot.fail(start ? robot.raw("start") : YAML::Node(), start ? "start" : "waypoints",
               std::string("planning robot.waypoints on ") + s.pipeline.world_path + ": " + e.what());
  }
  s.pipeline.path.waypoints_W = path.waypoints_W;
  if (!start) s.pipeline.start_pose = {path.waypoints_W.front().x(), path.waypoints_W.front().y(), path.start_yaw_rad};
}

double planned_duration_s(YamlMap& robot, const Scenario& s) {
  const auto& p = s.pipeline;
  const double duration_s =
      worldgen::drive_duration_s(p.path.waypoints_W, p.path.cruise_speed_mps, p.start_pose.yaw_rad);
  require_range(robot, "waypoints", "a planned drive of " + general(duration_s) + " s", duration_s <= 3600,
                "needs more than a scenario's 3600 s; give robot.waypoints or robot.start nearer the end");
  return duration_s;
}

void read_nav2_costmap(YamlMap costmap, Scenario& s) {
  layer::Nav2CostmapConfig& c = s.pipeline.nav2_costmap;
  costmap.require("width_m", c.width_m);
  costmap.require("height_m", c.height_m);
  const bool nav2_layer = s.pipeline.layer_type != layer::LayerType::kStvl;
  if (nav2_layer) c.resolution_m = s.pipeline.map.voxel_size_m;  // a nav2 layer's grid has one resolution
  costmap.get("resolution_m", c.resolution_m);
  if (nav2_layer)
    require_range(costmap, "resolution_m", c.resolution_m,
                  std::abs(c.resolution_m - s.pipeline.map.voxel_size_m) <= 1e-12,
                  "must equal map.voxel_size (" + general(s.pipeline.map.voxel_size_m) +
                      " m) with a nav2 layer, the one resolution of its grid (or leave it out)");
  costmap.get("rolling_window", c.rolling_window);
  costmap.get("combination_method", c.combination_method);
  costmap.get("track_unknown_space", c.track_unknown_space);
  costmap.get("touch_cleared_cells", c.touch_cleared_cells);
  require_range(costmap, "width_m", c.width_m, c.width_m > 0.0, "must be > 0 m");
  require_range(costmap, "height_m", c.height_m, c.height_m > 0.0, "must be > 0 m");
  validate_keys({{"width_m", &costmap, "width_m"},
                 {"height_m", &costmap, "height_m"},
                 {"resolution_m", &costmap, "resolution_m"},
                 {"combination_method", &costmap, "combination_method"}},
                [&] { c.validate(); });
  costmap.finish();
}

void read_layer_type(YamlMap& map, Scenario& s) {
  std::string type = layer::to_string(s.pipeline.layer_type);
  map.get("layer_type", type);
  validate_keys({{"layer_type", &map, "layer_type"}}, [&] { s.pipeline.layer_type = layer::parse_layer_type(type); });
  if (!map.has("nav2_layer")) return;
  if (s.pipeline.layer_type == layer::LayerType::kStvl)
    map.fail(map.raw("nav2_layer"), "nav2_layer", "needs map.layer_type nav2_voxel or nav2_obstacle");
  YamlMap n = map.map("nav2_layer");
  layer::Nav2LayerParams& p = s.pipeline.nav2_layer;
  n.get("z_voxels", p.z_voxels);
  n.get("z_resolution", p.z_resolution_m);
  n.get("origin_z", p.origin_z_m);
  n.get("unknown_threshold", p.unknown_threshold);
  n.get("mark_threshold", p.mark_threshold);
  n.get("min_obstacle_height", p.min_obstacle_height_m);
  n.get("max_obstacle_height", p.max_obstacle_height_m);
  n.get("combination_method", p.combination_method);
  n.get("footprint_clearing_enabled", p.footprint_clearing_enabled);
  n.get("publish_voxel_map", p.publish_voxel_map);
  std::string marking = layer::to_string(p.marking_range),
              purge = p.purge_rule == layer::nav2::PurgeRule::kMain ? "main" : "jazzy";
  n.get("nav2_marking_range", marking);
  n.get("nav2_purge_rule", purge);
  validate_keys({{"nav2_marking_range", &n, "nav2_marking_range"}},
                [&] { p.marking_range = layer::parse_nav2_marking_range(marking); });
  if (purge != "jazzy" && purge != "main")
    n.fail(n.raw("nav2_purge_rule"), "nav2_purge_rule", "expected jazzy or main");
  p.purge_rule = purge == "main" ? layer::nav2::PurgeRule::kMain : layer::nav2::PurgeRule::kJazzy;
  std::vector<Blame> blame;
  for (const char* key : {"z_voxels", "z_resolution", "origin_z", "unknown_threshold", "mark_threshold",
                          "min_obstacle_height", "max_obstacle_height", "combination_method"})
    blame.push_back({key, &n, key});
  validate_keys(blame, [&] { p.validate(); });
  n.finish();
}

void read_nav2_ranges(YamlMap& o, layer::Nav2SourceRanges& nav2) {
  const std::pair<const char*, double*> ranges[] = {{"obstacle_max_range", &nav2.obstacle_max_range_m},
                                                    {"obstacle_min_range", &nav2.obstacle_min_range_m},
                                                    {"raytrace_max_range", &nav2.raytrace_max_range_m},
                                                    {"raytrace_min_range", &nav2.raytrace_min_range_m}};
  for (const auto& [key, value] : ranges) {
    o.get(key, *value);
    require_range(o, key, *value, std::isfinite(*value) && *value >= 0.0 && *value <= 100.0, "must lie in [0, 100] m");
  }
}

}  // namespace stvl::config::scenario_detail

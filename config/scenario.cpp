#include "config/scenario.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <memory>
#include <sstream>

#include "config/ros_binding.hpp"
#include "config/ros_nav2_layer.hpp"
#include "config/scenario_detail.hpp"
#include "config/stvl_keys.hpp"
#include "config/yaml_reader.hpp"
#include "mapping/footprint.hpp"
#include "sim/world.hpp"

namespace stvl::config {
namespace {

using namespace scenario_detail;

// map.observation as read: every camera's source starts from it.
struct ObservationDefaults {
  mapping::ObservationSource source;
  layer::Nav2SourceRanges nav2;  // nav2's layers' ranges (obstacle_max_range, ...)
  std::optional<double> hfov_rad, vfov_rad;
  std::shared_ptr<YamlMap> yaml;  // null when the file has no map.observation
};

void read_robot(YamlMap robot, Scenario& s, std::vector<std::optional<YamlMap>>& overrides, const std::string& base_dir,
                const worldgen::MapWorld* map_world, bool closed_loop) {
  std::vector<double> start{0.0, 0.0, 0.0};
  robot.get("start", start);
  if (start.size() != 3) robot.fail(robot.raw("start"), "start", "expected [x_m, y_m, yaw_deg]");
  require_range(robot, "start", "non-finite values", std::isfinite(start[0] + start[1] + start[2]), "must be finite");
  s.pipeline.start_pose = {start[0], start[1], start[2] * kRadPerDeg};
  std::vector<std::vector<double>> waypoints;
  const bool plan = map_world && !robot.has("waypoints");  // nav2_map without waypoints: planned for the robot below
  if (!plan && !closed_loop) robot.require("waypoints", waypoints);
  robot.get("waypoints", waypoints);  // closed loop: the goal's default
  s.pipeline.path.waypoints_W.clear();
  for (const auto& xy : waypoints) s.pipeline.path.waypoints_W.push_back(to_point2(xy, robot, "waypoints"));
  if (closed_loop) robot.get("speed_mps", s.pipeline.path.cruise_speed_mps);  // RPP's desired_linear_vel drives
  else robot.require("speed_mps", s.pipeline.path.cruise_speed_mps);
  robot.get("loop", s.pipeline.path.loop);        // soak (issue #270): a patrol that never ends
  robot.get("reverse", s.pipeline.path.reverse);  // backwards, the rear leading (nav2 #5476's reversing robot)
  read_urdf_robot(robot, s, base_dir);
  if (plan) plan_on_map(*map_world, robot, s);
  if (!closed_loop || s.pipeline.path.waypoints_W.size() >= 2)
    validate_keys({{"waypoints", &robot, "waypoints"},
                   {"waypoint", &robot, "waypoints"},
                   {"cruise_speed_mps", &robot, "speed_mps"}},
                  [&] { sim::PathFollower(s.pipeline.sim.follower).set_path(s.pipeline.path); });
  if (robot.has("camera_mount")) {
    auto mount = robot.map("camera_mount");
    auto& m = s.pipeline.sim.camera_mount;
    double pitch_deg = m.pitch_rad / kRadPerDeg;
    mount.get("height_m", m.height_m);
    mount.get("pitch_deg", pitch_deg);
    mount.get("forward_offset_m", m.forward_offset_m);
    m.pitch_rad = pitch_deg * kRadPerDeg;
    mount.finish();
    s.camera().mount = m;  // the model's camera site follows it too (the legacy range checks come from there)
  }
  if (robot.has("cameras")) read_cameras(robot, s, overrides);
  robot.get("geoms_seen_by_cameras", s.pipeline.robot_geoms_seen);
  if (!s.pipeline.robot_geoms_seen.empty()) try {  // names checked against the world here, for file:line
      pipeline::load_world(s.pipeline).show_robot_geoms_to_cameras(s.pipeline.robot_geoms_seen);
    } catch (const std::invalid_argument& e) {
      robot.fail(robot.raw("geoms_seen_by_cameras"), "geoms_seen_by_cameras", e.what());
    }
  if (robot.has("odometry_drift")) {
    auto drift = robot.map("odometry_drift");
    auto& o = s.pipeline.sim.odometry;
    drift.get("enabled", o.drift);
    drift.get("left_wheel_radius_error", o.left_wheel_radius_error);
    drift.get("right_wheel_radius_error", o.right_wheel_radius_error);
    drift.get("track_width_error", o.track_width_error);
    drift.get("linear_noise_std_mps", o.linear_noise_std_mps);
    drift.get("angular_noise_std_radps", o.angular_noise_std_radps);
    for (const char* key : {"left_wheel_radius_error", "right_wheel_radius_error", "track_width_error"}) {
      double value = 0.0;
      drift.get(key, value);
      require_range(drift, key, value, std::isfinite(value) && std::abs(value) < 0.5, "must lie in (-0.5, 0.5)");
    }
    for (const char* key : {"linear_noise_std_mps", "angular_noise_std_radps"}) {
      double value = 0.0;
      drift.get(key, value);
      require_range(drift, key, value, std::isfinite(value) && value >= 0.0, "must be finite and >= 0");
    }
    drift.finish();
  }
  robot.finish();
}

void read_moving_bodies(YamlMap& root, Scenario& s) {
  for (auto& body : root.list_of_maps("moving_bodies")) {
    sim::MocapTrack track;
    body.require("body", track.body);
    for (auto& key : body.list_of_maps("keyframes")) {
      sim::MocapKeyframe frame;
      std::vector<double> position;
      key.require("t", frame.time_s);
      key.require("position", position);
      if (position.size() != 3) key.fail(key.raw("position"), "position", "expected [x, y, z]");
      frame.position_W = {position[0], position[1], position[2]};
      if (key.has("yaw_deg")) {
        double yaw_deg = 0.0;
        key.get("yaw_deg", yaw_deg);
        frame.yaw_rad = yaw_deg * kRadPerDeg;
      }
      key.finish();
      track.keyframes.push_back(frame);
    }
    if (track.keyframes.empty()) body.fail(body.raw("keyframes"), "keyframes", "at least one keyframe is required");
    if (body.has("repeat_s")) {  // soak (issue #270): a walk that repeats
      double repeat_s = 0.0;
      body.get("repeat_s", repeat_s);
      const double span_s = track.keyframes.back().time_s - track.keyframes.front().time_s;
      require_range(body, "repeat_s", repeat_s, std::isfinite(repeat_s) && repeat_s > 0 && repeat_s >= span_s,
                    "must be finite, > 0 and at least the keyframes' span " + general(span_s) + " s");
      track.repeat_s = repeat_s;
    }
    body.finish();
    s.pipeline.moving_bodies.push_back(std::move(track));
  }
}

// `src`; the FOV angles stay unset (the camera's) unless given.
void read_observation(YamlMap& o, mapping::ObservationSource& src, layer::Nav2SourceRanges& nav2,
                      std::optional<double>& hfov, std::optional<double>& vfov) {
  read_source_keys(o, src, kReadByScenario, {"horizontal_fov_angle", "vertical_fov_angle"});
  read_nav2_ranges(o, nav2);
  read_clearing_model(o, src);
  get_optional(o, "horizontal_fov_angle", hfov);
  get_optional(o, "vertical_fov_angle", vfov);
  o.finish();
}

// A camera's source: the map's observation defaults, the camera's FOV unless given, then its own overrides.
void apply_observation(pipeline::CameraConfig& camera, const ObservationDefaults& defaults, std::optional<YamlMap> own,
                       mapping::ClearingMode mode) {
  auto& src = camera.sources.front().params;
  src = defaults.source;
  camera.sources.front().nav2 = defaults.nav2;
  std::optional<double> hfov = defaults.hfov_rad, vfov = defaults.vfov_rad;
  if (own) read_observation(*own, src, camera.sources.front().nav2, hfov, vfov);
  src.horizontal_fov_rad = hfov.value_or(camera.intrinsics.hfov_rad());
  src.vertical_fov_rad = vfov.value_or(camera.intrinsics.vfov_rad());
  YamlMap* o = own ? &*own : defaults.yaml.get();
  if (src.clear_on_no_return && mode != mapping::ClearingMode::kRaycast) {
    YamlMap* where = own && own->has("clear_on_no_return") ? &*own : defaults.yaml.get();
    where->fail(where->raw("clear_on_no_return"), "clear_on_no_return",
                "needs map.clearing_mode: raycast (frustum clearing walks no rays)");
  }
  if (src.drop_when_not_current && !(src.expected_update_rate_s > 0.0)) {
    YamlMap* where = own && own->has("drop_when_not_current") ? &*own : defaults.yaml.get();
    where->fail(where->raw("drop_when_not_current"), "drop_when_not_current",
                "needs expected_update_rate > 0 s (with 0 a source is always current)");
  }
  if (!o) {
    try {
      src.validate();
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("camera '" + camera.name + "': " + e.what());
    }
    return;
  }
  std::vector<Blame> blame;  // every number of the source the table gives, named in its own mapping
  for (const StvlKey& key : stvl_keys())
    if (key.scope == StvlScope::kSource && key.number && (key.read_by & kReadByScenario))
      blame.push_back({key.name, o, key.name});
  validate_keys(blame, [&] { src.validate(); });
}

// map.ros_params: STVL's own keys come from the file, the bench's (clearing_mode, ...) stay here.
void read_ros_params(YamlMap& map, Scenario& s, const std::string& base_dir) {
  RosParamsRef ref;
  map.require("ros_params", ref.path);
  require_range(map, "ros_params", "an empty path", !ref.path.empty(), "must not be empty");
  map.get("layer", ref.layer);
  map.get("costmap", ref.costmap);
  ref.path = std::filesystem::path(ref.path).is_absolute()
                 ? ref.path
                 : (std::filesystem::path(base_dir) / ref.path).lexically_normal().string();
  for (const char* key : {"voxel_size", "voxel_decay", "decay_model", "mark_threshold", "observation",
                          "update_footprint_enabled", "robot_radius", "footprint", "layer_type", "nav2_layer"})
    if (map.has(key))
      map.fail(map.raw(key), key,
               "comes from the ROS parameter file (map.ros_params: " + ref.path + "); remove it here");
  s.ros_params = ref;
}

// map.update_footprint_enabled, map.robot_radius, map.footprint (STVL's footprint clearing; nav2's keys).
void read_footprint(YamlMap& map, Scenario& s) {
  mapping::StvlConfig& m = s.pipeline.map;
  map.get("update_footprint_enabled", m.update_footprint_enabled);
  map.get("clear_footprint_voxels_below", m.clear_footprint_voxels_below_m);
  require_range(map, "clear_footprint_voxels_below", m.clear_footprint_voxels_below_m,
                std::isfinite(m.clear_footprint_voxels_below_m) && m.clear_footprint_voxels_below_m >= 0.0 &&
                    m.clear_footprint_voxels_below_m <= 3.0,
                "must lie in [0, 3] m");
  if (map.has("robot_radius") && map.has("footprint"))
    map.fail(map.raw("footprint"), "footprint", "give either footprint or robot_radius, not both");
  if (map.has("robot_radius")) {
    double radius_m = 0.0;
    map.get("robot_radius", radius_m);
    require_range(map, "robot_radius", radius_m, std::isfinite(radius_m) && radius_m > 0.0, "must be finite and > 0 m");
    m.footprint_B = mapping::footprint_from_radius(radius_m);
    s.footprint_source = "map.robot_radius";
  }
  if (map.has("footprint")) {
    std::vector<std::vector<double>> points;
    map.get("footprint", points);
    if (points.size() < 3) map.fail(map.raw("footprint"), "footprint", "needs at least three [x, y] points");
    m.footprint_B.clear();
    for (const auto& xy : points) {
      const Eigen::Vector2d p = to_point2(xy, map, "footprint");
      if (!p.allFinite()) map.fail(map.raw("footprint"), "footprint", "points must be finite");
      m.footprint_B.push_back(p);
    }
    s.footprint_source = "map.footprint";
  }
  if (m.clear_footprint_voxels_below_m > 0.0 && m.footprint_B.empty() && !map.has("ros_params") &&
      !s.pipeline.urdf_robot)
    map.fail(map.raw("clear_footprint_voxels_below"), "clear_footprint_voxels_below",
             "needs the robot's footprint (map.robot_radius or map.footprint)");
}

void read_map(YamlMap map, Scenario& s, ObservationDefaults& observation, const std::string& base_dir) {
  auto& m = s.pipeline.map;
  if (map.has("ros_params")) read_ros_params(map, s, base_dir);
  map.get("voxel_size", m.voxel_size_m);
  map.get("voxel_decay", m.voxel_decay_s);
  std::string decay = mapping::to_string(m.decay_model), mode = mapping::to_string(m.clearing_mode),
              walk = mapping::to_string(m.clearing_walk), rounding = mapping::to_string(m.mark_rounding),
              geometry = mapping::to_string(m.frustum_geometry), grouping = mapping::to_string(m.update_grouping),
              band = mapping::to_string(m.costmap_band), timing = mapping::to_string(m.costmap_timing);
  map.get("decay_model", decay);
  map.get("clearing_mode", mode);
  map.get("clearing_walk", walk);
  map.get("mark_rounding", rounding);
  map.get("frustum_geometry", geometry);
  map.get("update_grouping", grouping);
  map.get("costmap_band", band);
  map.get("costmap_timing", timing);
  validate_keys({{"decay_model", &map, "decay_model"}}, [&] { m.decay_model = mapping::parse_decay_model(decay); });
  validate_keys({{"clearing_mode", &map, "clearing_mode"}},
                [&] { m.clearing_mode = mapping::parse_clearing_mode(mode); });
  validate_keys({{"clearing_walk", &map, "clearing_walk"}},
                [&] { m.clearing_walk = mapping::parse_clearing_walk(walk); });
  validate_keys({{"mark_rounding", &map, "mark_rounding"}},
                [&] { m.mark_rounding = mapping::parse_mark_rounding(rounding); });
  validate_keys({{"frustum_geometry", &map, "frustum_geometry"}},
                [&] { m.frustum_geometry = mapping::parse_frustum_geometry(geometry); });
  validate_keys({{"update_grouping", &map, "update_grouping"}},
                [&] { m.update_grouping = mapping::parse_update_grouping(grouping); });
  validate_keys({{"costmap_band", &map, "costmap_band"}}, [&] { m.costmap_band = mapping::parse_costmap_band(band); });
  validate_keys({{"costmap_timing", &map, "costmap_timing"}},
                [&] { m.costmap_timing = mapping::parse_costmap_timing(timing); });
  map.get("mark_threshold", m.mark_threshold);
  map.get("update_frequency", m.update_frequency_hz);
  int expiry_leaves = static_cast<int>(m.expiry_leaves_per_update);
  map.get("expiry_leaves_per_update", expiry_leaves);
  require_range(map, "expiry_leaves_per_update", expiry_leaves, expiry_leaves >= 1, "must be >= 1");
  m.expiry_leaves_per_update = static_cast<std::size_t>(expiry_leaves);
  map.get("publish_period_s", s.outputs.publish_period_s);
  require_range(map, "publish_period_s", s.outputs.publish_period_s,
                std::isfinite(s.outputs.publish_period_s) && s.outputs.publish_period_s > 0,
                "must be finite and > 0 s");
  validate_keys({{"voxel_size", &map, "voxel_size"},
                 {"voxel_decay", &map, "voxel_decay"},
                 {"decay_model", &map, "decay_model"},
                 {"mark_threshold", &map, "mark_threshold"},
                 {"update_frequency", &map, "update_frequency"}},
                [&] { m.validate(); });
  read_footprint(map, s);
  read_layer_type(map, s);
  if (map.has("nav2_costmap")) read_nav2_costmap(map.map("nav2_costmap"), s);
  if (map.has("observation")) {
    observation.yaml = std::make_shared<YamlMap>(map.map("observation"));
    read_observation(*observation.yaml, observation.source, observation.nav2, observation.hfov_rad,
                     observation.vfov_rad);
  }
  map.finish();
}

// world (an MJCF file, relative to the scenario's folder) or nav2_map (a map to build the world from, returned).
std::shared_ptr<const worldgen::MapWorld> read_world(YamlMap& root, Scenario& s, const std::string& base_dir) {
  std::string world;
  std::shared_ptr<const worldgen::MapWorld> map_world;  // nav2_map: the world built from a nav2 map instead
  if (root.has("nav2_map") && root.has("world"))
    root.fail(root.raw("nav2_map"), "nav2_map",
              "give either world (an MJCF file) or nav2_map (a map to build one from), not both");
  if (root.has("nav2_map")) map_world = read_nav2_map(root.map("nav2_map"), s, base_dir);
  else root.require("world", world);
  require_range(root, "world", "an empty path", map_world || !world.empty(), "must not be empty");
  if (!map_world)
    s.pipeline.world_path = std::filesystem::path(world).is_absolute()
                                ? world
                                : (std::filesystem::path(base_dir) / world).lexically_normal().string();
  return map_world;
}

// duration_s, stop_at_path_end and the robot (its cameras' own observation keys into camera_overrides); a world
// built from a nav2 map runs for the planned drive unless waypoints or duration_s are given.
void read_run_and_robot(YamlMap& root, Scenario& s, std::vector<std::optional<YamlMap>>& camera_overrides,
                        const std::string& base_dir, const worldgen::MapWorld* map_world, bool closed_loop) {
  root.get("duration_s", s.duration_s);
  require_range(root, "duration_s", s.duration_s, s.duration_s > 0 && s.duration_s <= 3600, "must lie in (0, 3600] s");
  root.get("stop_at_path_end", s.stop_at_path_end);
  read_robot(root.map("robot"), s, camera_overrides, base_dir, map_world, closed_loop);
  if (YamlMap robot = root.map("robot"); map_world && !robot.has("waypoints") && !root.has("duration_s"))
    s.duration_s = planned_duration_s(robot, s);
  if (s.pipeline.path.loop) {  // a looping path has no end to stop at
    if (root.has("stop_at_path_end") && s.stop_at_path_end)
      root.fail(root.raw("stop_at_path_end"), "stop_at_path_end",
                "robot.loop never reaches an end; set it false or leave it out");
    s.stop_at_path_end = false;
  }
}

// The sensors and the map: the top-level camera, filter, map, each camera's observation sources, and the layer of
// map.ros_params when it names one.
void read_sensors_and_map(YamlMap& root, Scenario& s, const std::vector<std::optional<YamlMap>>& camera_overrides,
                          const std::string& base_dir) {
  if (root.has("camera")) {
    if (root.map("robot").has("cameras"))
      root.fail(root.raw("camera"), "camera", "robot.cameras gives the cameras; move these keys into its entries");
    read_camera(root.map("camera"), s);
  }
  if (root.has("filter")) read_filter(root.map("filter"), s);
  ObservationDefaults observation;
  observation.source.clearing = true;
  if (root.has("map")) read_map(root.map("map"), s, observation, base_dir);
  for (const auto& own : camera_overrides)
    if (own && s.ros_params)
      own->fail(YAML::Node(), "", "the sources come from map.ros_params; remove this observation");
  for (std::size_t i = 0; i < s.pipeline.cameras.size(); ++i)
    apply_observation(s.pipeline.cameras[i], observation, camera_overrides[i], s.pipeline.map.clearing_mode);
  if (s.ros_params && ros_layer_is_nav2(s.ros_params->path, s.ros_params->layer, s.ros_params->costmap)) {
    // nav2's VoxelLayer or ObstacleLayer: the plugin decides the layer; the filter stays the scenario's.
    const RosNav2Layer layer = load_ros_nav2_layer(s.ros_params->path, s.ros_params->layer, s.ros_params->costmap);
    apply_ros_nav2_layer(layer, s.pipeline);
    s.footprint_source = "ros_params " + layer.footprint_source + " (" + s.ros_params->path + ")";
  } else if (s.ros_params) {
    const RosStvlLayer layer = load_ros_stvl_layer(s.ros_params->path, s.ros_params->layer, s.ros_params->costmap);
    apply_ros_layer(layer, s.pipeline, !root.has("filter"));
    const bool footprint = layer.footprint && !layer.footprint->empty();
    s.footprint_source =
        footprint || layer.robot_radius_m
            ? std::string("ros_params ") + (footprint ? "footprint" : "robot_radius") + " (" + s.ros_params->path + ")"
            : "";
  }
}

Scenario parse_root(YamlMap root, const std::string& base_dir) {
  Scenario s;
  s.file = root.file();
  root.require("name", s.name);
  require_range(root, "name", "an empty name", !s.name.empty(), "must not be empty");
  const std::shared_ptr<const worldgen::MapWorld> map_world = read_world(root, s, base_dir);
  root.get("seed", s.pipeline.seed);
  std::vector<std::optional<YamlMap>> camera_overrides{std::nullopt};
  const bool closed_loop = navigation_closed_loop(root);
  read_run_and_robot(root, s, camera_overrides, base_dir, map_world.get(), closed_loop);
  read_moving_bodies(root, s);
  read_sensors_and_map(root, s, camera_overrides, base_dir);
  if (root.has("tf")) read_tf(root.map("tf"), s);
  if (root.has("localization")) read_localization(root.map("localization"), s);
  complete_footprint(s);
  if (root.has("navigation"))
    read_navigation(root.map("navigation"), s, s.pipeline.path.waypoints_W, base_dir, map_world.get());
  if (closed_loop) {  // nav2 drives: no path to follow or stop at
    if (root.has("stop_at_path_end") && s.stop_at_path_end)
      root.fail(root.raw("stop_at_path_end"), "stop_at_path_end",
                "navigation.mode closed_loop stops when the navigation ends; leave it out");
    s.stop_at_path_end = false;
    s.pipeline.path.waypoints_W.clear();
    s.pipeline.sim.localization.layer_in_odom = true;  // the run's layer is the local costmap's (global: map)
  }
  if (root.has("evaluation")) read_evaluation(root.map("evaluation"), s);
  if (root.has("checks")) read_checks(root.map("checks"), s);
  // The default checks (evaluation/checks.hpp) where the scenario sets no threshold of its own.
  if (!s.checks.costmap_precision_min) s.checks.costmap_precision_min = evaluation::kDefaultCostmapPrecisionMin;
  if (!s.checks.path_free_lethal_max) s.checks.path_free_lethal_max = evaluation::kDefaultPathFreeLethalMax;
  root.finish();
  s.pipeline.filter.csnb.seed = s.pipeline.seed;
  s.pipeline.sim.odometry.seed = s.pipeline.sim.localization.seed = s.pipeline.seed;
  try {
    pipeline::validate_cameras(s.pipeline);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(s.file + ": " + e.what());
  }
  return s;
}

}  // namespace

Scenario parse_scenario(const std::string& yaml_text, const std::string& file_name, const std::string& base_dir) {
  return parse_root(YamlMap(load_yaml_string(yaml_text, file_name), file_name, ""), base_dir);
}

Scenario load_scenario(const std::string& path, const std::vector<std::string>& sets) {
  YAML::Node node = load_yaml_file(path);
  for (const auto& assignment : sets) set_yaml_path(node, assignment);
  try {
    return parse_root(YamlMap(node, path, ""), std::filesystem::path(path).parent_path().string());
  } catch (const std::invalid_argument& e) {
    // "file:line: dotted.key: message" about a key an assignment set: the assignment is to blame, not the line.
    const std::string message = e.what();
    for (const auto& assignment : sets) {
      const std::string key = ": " + assignment.substr(0, assignment.find('=')) + ": ";
      if (const std::size_t at = message.find(key); at != std::string::npos)
        throw std::invalid_argument("--set " + assignment + ": " + message.substr(at + key.size()) + " (in " + path +
                                    ")");
    }
    throw;
  }
}

std::string default_scenario_path() { return std::string(STVL_SOURCE_DIR) + "/scenarios/office_corridor.yaml"; }

namespace {
template <typename F>
void override_option(const char* option, F&& apply) {
  try {
    apply();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string(option) + ": " + e.what());
  }
}
}  // namespace

void apply_overrides(Scenario& s, const ScenarioOverrides& o) {
  // Validated on a copy, so a rejected override leaves the scenario as it was.
  Scenario r = s;
  if (o.seed)
    r.pipeline.seed = *o.seed, r.pipeline.filter.csnb.seed = *o.seed,
    r.pipeline.sim.odometry.seed = r.pipeline.sim.localization.seed = *o.seed;
  if (o.filter_type)
    override_option("--filter", [&] { r.pipeline.filter.type = filter::parse_filter_type(*o.filter_type); });
  if (o.device) override_option("--device", [&] { r.pipeline.filter.device = filter::parse_device(*o.device); });
  if (o.memory) override_option("--memory", [&] { r.pipeline.filter.memory = filter::parse_memory_mode(*o.memory); });
  if (o.voxel_size_m) {
    override_option("--voxel-size", [&] {
      r.pipeline.map.voxel_size_m = *o.voxel_size_m;
      r.pipeline.filter.voxel.voxel_size_m = *o.voxel_size_m;
      r.pipeline.filter.csnb.voxel_size_m = *o.voxel_size_m;
      r.pipeline.map.validate();
    });
  }
  if (o.duration_s) {
    if (!(*o.duration_s > 0 && *o.duration_s <= 3600))
      throw std::invalid_argument("--duration: must lie in (0, 3600] s, got " + std::to_string(*o.duration_s));
    r.duration_s = *o.duration_s;
  }
  if (o.gl_backend)
    override_option("--gl", [&] {
      for (auto& c : r.pipeline.cameras) c.gl_backend = sensors::parse_gl_backend(*o.gl_backend);
    });
  if (o.noise)
    for (auto& c : r.pipeline.cameras) c.noise.enabled = *o.noise;
  s = std::move(r);
}

evaluation::EvaluationConfig evaluation_config(const Scenario& s) {
  evaluation::EvaluationConfig e = s.evaluation;
  e.voxel_size_m = s.pipeline.map.voxel_size_m;
  const layer::HeightBand band = pipeline::marking_band(s.pipeline);
  e.min_obstacle_height_m = band.min_m;
  e.max_obstacle_height_m = band.max_m;
  e.costmap_every_voxel = s.pipeline.map.costmap_band == mapping::CostmapBand::kEveryVoxel;
  e.cameras = s.pipeline.cameras.size();
  e.robot_footprint_B = s.pipeline.map.footprint_B;
  e.footprint_clearing = s.pipeline.map.update_footprint_enabled;
  if (s.pipeline.layer_type != layer::LayerType::kStvl) {
    // nav2's layers mark inside the sources' band and their own (the voxel layer: below its grid's top too).
    const layer::Nav2LayerParams& n = s.pipeline.nav2_layer;
    e.min_obstacle_height_m = std::max(e.min_obstacle_height_m, n.min_obstacle_height_m);
    e.max_obstacle_height_m = std::min(e.max_obstacle_height_m, n.max_obstacle_height_m);
    if (s.pipeline.layer_type == layer::LayerType::kNav2Voxel)
      e.max_obstacle_height_m = std::min(e.max_obstacle_height_m, n.origin_z_m + n.z_voxels * n.z_resolution_m);
    e.footprint_clearing = n.footprint_clearing_enabled;
    e.layer_has_voxels = s.pipeline.layer_type == layer::LayerType::kNav2Voxel;
    e.costmap_projected = false;
    e.nav2_marking_range = true;
  }
  e.path_W = s.pipeline.path.waypoints_W;  // a looping path is closed: its last leg goes back to the first point
  if (s.pipeline.path.loop && e.path_W.size() > 1 && e.path_W.back() != e.path_W.front())
    e.path_W.push_back(e.path_W.front());
  return e;
}

}  // namespace stvl::config

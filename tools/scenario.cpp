#include "tools/scenario.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tools/yaml_reader.hpp"

namespace stvl::tools {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

template <typename F>
void with_context(const YamlMap& map, const std::string& key, F&& validate) {
  try {
    validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(map.file() + ": " + map.location(key) + ": " + e.what());
  }
}

Eigen::Vector2d to_point2(const std::vector<double>& xy, YamlMap& map, const std::string& key) {
  if (xy.size() != 2) map.fail(map.raw(key), key, "expected [x, y] points");
  return {xy[0], xy[1]};
}

void read_robot(YamlMap robot, Scenario& s) {
  std::vector<double> start{0.0, 0.0, 0.0};
  robot.get("start", start);
  if (start.size() != 3) robot.fail(robot.raw("start"), "start", "expected [x_m, y_m, yaw_deg]");
  s.start_pose = {start[0], start[1], start[2] * kDegToRad};
  std::vector<std::vector<double>> waypoints;
  robot.require("waypoints", waypoints);
  s.path.waypoints_W.clear();
  for (const auto& xy : waypoints) s.path.waypoints_W.push_back(to_point2(xy, robot, "waypoints"));
  robot.require("speed_mps", s.path.cruise_speed_mps);
  with_context(robot, "waypoints", [&] { sim::PathFollower().set_path(s.path); });

  if (robot.has("camera_mount")) {
    auto mount = robot.map("camera_mount");
    auto& m = s.sim.camera_mount;
    double pitch_deg = m.pitch_rad / kDegToRad;
    mount.get("height_m", m.height_m);
    mount.get("pitch_deg", pitch_deg);
    mount.get("forward_offset_m", m.forward_offset_m);
    m.pitch_rad = pitch_deg * kDegToRad;
    mount.finish();
  }
  if (robot.has("odometry_drift")) {
    auto drift = robot.map("odometry_drift");
    auto& o = s.sim.odometry;
    drift.get("enabled", o.drift);
    drift.get("left_wheel_radius_error", o.left_wheel_radius_error);
    drift.get("right_wheel_radius_error", o.right_wheel_radius_error);
    drift.get("track_width_error", o.track_width_error);
    drift.get("linear_noise_std_mps", o.linear_noise_std_mps);
    drift.get("angular_noise_std_radps", o.angular_noise_std_radps);
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
        frame.yaw_rad = yaw_deg * kDegToRad;
      }
      key.finish();
      track.keyframes.push_back(frame);
    }
    if (track.keyframes.empty()) body.fail(body.raw("keyframes"), "keyframes", "at least one keyframe is required");
    body.finish();
    s.moving_bodies.push_back(std::move(track));
  }
}

void read_camera(YamlMap camera, Scenario& s) {
  auto& c = s.camera;
  camera.get("preset", c.preset);
  if (c.preset == "d435_848x480") {
    c.intrinsics = sensors::CameraIntrinsics::d435_848x480();
  } else if (c.preset == "d435_640x480") {
    c.intrinsics = sensors::CameraIntrinsics::d435_640x480();
  } else if (c.preset == "custom") {
    auto in = camera.map("intrinsics");
    in.require("width", c.intrinsics.width);
    in.require("height", c.intrinsics.height);
    in.require("fx", c.intrinsics.fx);
    in.require("fy", c.intrinsics.fy);
    in.require("cx", c.intrinsics.cx);
    in.require("cy", c.intrinsics.cy);
    in.finish();
  } else {
    camera.fail(camera.raw("preset"), "preset", "unknown preset '" + c.preset + "' (d435_848x480, d435_640x480, custom)");
  }
  camera.get("min_range_m", c.intrinsics.min_range_m);
  camera.get("max_range_m", c.intrinsics.max_range_m);
  camera.get("rate_hz", c.intrinsics.rate_hz);
  with_context(camera, "intrinsics", [&] { c.intrinsics.validate(); });
  std::string backend = sensors::to_string(c.gl_backend);
  camera.get("gl_backend", backend);
  with_context(camera, "gl_backend", [&] { c.gl_backend = sensors::parse_gl_backend(backend); });
  if (camera.has("noise")) {
    auto noise = camera.map("noise");
    auto& n = c.noise;
    noise.get("enabled", n.enabled);
    noise.get("baseline_m", n.baseline_m);
    noise.get("subpixel", n.subpixel);
    noise.get("disparity_step_px", n.disparity_step_px);
    noise.get("edge_jump_m", n.edge_jump_m);
    noise.get("edge_probability", n.edge_probability);
    noise.get("edge_invalid_fraction", n.edge_invalid_fraction);
    noise.get("dropout_probability", n.dropout_probability);
    noise.get("holes_per_frame", n.holes_per_frame);
    noise.get("hole_max_radius_px", n.hole_max_radius_px);
    noise.finish();
    with_context(camera, "noise", [&] { n.validate(); });
  }
  camera.finish();
}

void read_filter(YamlMap filter, Scenario& s) {
  auto& f = s.filter;
  std::string type = filter::to_string(f.type), device = filter::to_string(f.device),
              memory = filter::to_string(f.memory);
  filter.get("type", type);
  filter.get("device", device);
  filter.get("memory", memory);
  with_context(filter, "type", [&] { f.type = filter::parse_filter_type(type); });
  with_context(filter, "device", [&] { f.device = filter::parse_device(device); });
  with_context(filter, "memory", [&] { f.memory = filter::parse_memory_mode(memory); });
  filter.get("cpu_threads", f.cpu_threads);
  if (filter.has("passthrough")) {
    auto p = filter.map("passthrough");
    p.get("enabled", f.passthrough_enabled);
    p.get("min_z_m", f.passthrough.min_z_m);
    p.get("max_z_m", f.passthrough.max_z_m);
    p.finish();
  }
  if (filter.has("voxel")) {
    auto v = filter.map("voxel");
    v.get("voxel_size_m", f.voxel.voxel_size_m);
    v.get("min_points_per_voxel", f.voxel.min_points_per_voxel);
    v.finish();
  }
  if (filter.has("csnb")) {
    auto c = filter.map("csnb");
    c.get("voxel_size_m", f.csnb.voxel_size_m);
    c.get("max_neighbours", f.csnb.max_neighbours);
    c.get("batch_size", f.csnb.batch_size);
    c.get("grid_exponent", f.csnb.grid_exponent);
    c.finish();
  }
  filter.finish();
}

void read_map(YamlMap map, Scenario& s) {
  auto& m = s.map;
  map.get("voxel_size", m.voxel_size);
  map.get("voxel_decay", m.voxel_decay);
  std::string decay = mapping::to_string(m.decay_model), mode = mapping::to_string(m.clearing_mode),
              walk = mapping::to_string(m.clearing_walk);
  map.get("decay_model", decay);
  map.get("clearing_mode", mode);
  map.get("clearing_walk", walk);
  with_context(map, "decay_model", [&] { m.decay_model = mapping::parse_decay_model(decay); });
  with_context(map, "clearing_mode", [&] { m.clearing_mode = mapping::parse_clearing_mode(mode); });
  with_context(map, "clearing_walk", [&] { m.clearing_walk = mapping::parse_clearing_walk(walk); });
  map.get("mark_threshold", m.mark_threshold);
  int expiry_leaves = static_cast<int>(m.expiry_leaves_per_update);
  map.get("expiry_leaves_per_update", expiry_leaves);
  if (expiry_leaves < 1) map.fail(map.raw("expiry_leaves_per_update"), "expiry_leaves_per_update", "must be >= 1");
  m.expiry_leaves_per_update = static_cast<std::size_t>(expiry_leaves);
  map.get("publish_period_s", s.voxel_grid_publish_period_s);
  with_context(map, "voxel_size", [&] { m.validate(); });
  if (map.has("observation")) {
    auto o = map.map("observation");
    auto& src = s.source;
    src.horizontal_fov_angle = std::nan("");
    src.vertical_fov_angle = std::nan("");
    o.get("marking", src.marking);
    o.get("clearing", src.clearing);
    o.get("obstacle_range", src.obstacle_range);
    o.get("min_obstacle_height", src.min_obstacle_height);
    o.get("max_obstacle_height", src.max_obstacle_height);
    o.get("horizontal_fov_angle", src.horizontal_fov_angle);
    o.get("vertical_fov_angle", src.vertical_fov_angle);
    o.get("min_z", src.min_z);
    o.get("max_z", src.max_z);
    o.get("decay_acceleration", src.decay_acceleration);
    o.finish();
  }
  map.finish();
}

void read_evaluation(YamlMap e, Scenario& s) {
  auto& ev = s.evaluation;
  e.get("recall_window_s", ev.recall_window_s);
  e.get("evaluate_every_s", ev.evaluate_every_s);
  e.get("tolerance_voxels", ev.tolerance_voxels);
  e.get("min_observed_voxels", ev.min_observed_voxels);
  e.get("phantom_min_cells", ev.phantom_min_cells);
  e.get("sample_depth_frames", ev.sample_depth_frames);
  if (!(ev.recall_window_s > 0) || !(ev.evaluate_every_s > 0) || ev.tolerance_voxels < 0 || ev.tolerance_voxels > 3 ||
      ev.min_observed_voxels < 1 || ev.phantom_min_cells < 1 || ev.sample_depth_frames < 0)
    e.fail(e.raw("recall_window_s"), "", "out of range (windows > 0, tolerance_voxels 0..3, counts >= 1)");
  e.finish();
}

template <typename T>
void get_optional(YamlMap& map, const std::string& key, std::optional<T>& value) {
  if (!map.has(key)) return;
  T v{};
  map.get(key, v);
  value = v;
}

void read_checks(YamlMap c, Scenario& s) {
  auto& ch = s.checks;
  get_optional(c, "f1_3d_min", ch.f1_3d_min);
  get_optional(c, "iou_3d_min", ch.iou_3d_min);
  get_optional(c, "costmap_precision_min", ch.costmap_precision_min);
  get_optional(c, "costmap_recall_min", ch.costmap_recall_min);
  c.get("all_obstacles_detected", ch.all_obstacles_detected);
  get_optional(c, "phantom_obstacles_max", ch.phantom_obstacles_max);
  get_optional(c, "clearing_latency_max_s", ch.clearing_latency_max_s);
  get_optional(c, "accuracy_p90_max_m", ch.accuracy_p90_max_m);
  c.finish();
}

Scenario parse_root(YamlMap root, const std::string& base_dir) {
  Scenario s;
  s.file = root.file();
  root.require("name", s.name);
  std::string world;
  root.require("world", world);
  s.world_path = std::filesystem::path(world).is_absolute() ? world : (std::filesystem::path(base_dir) / world).lexically_normal().string();
  root.get("seed", s.seed);
  root.get("duration_s", s.duration_s);
  if (!(s.duration_s > 0 && s.duration_s <= 3600)) root.fail(root.raw("duration_s"), "duration_s", "must be in (0, 3600] s");
  root.get("stop_at_path_end", s.stop_at_path_end);
  read_robot(root.map("robot"), s);
  read_moving_bodies(root, s);
  if (root.has("camera")) read_camera(root.map("camera"), s);
  if (root.has("filter")) read_filter(root.map("filter"), s);
  s.source.clearing = true;
  s.source.horizontal_fov_angle = std::nan("");
  s.source.vertical_fov_angle = std::nan("");
  if (root.has("map")) read_map(root.map("map"), s);
  if (root.has("evaluation")) read_evaluation(root.map("evaluation"), s);
  if (root.has("checks")) read_checks(root.map("checks"), s);
  root.finish();
  if (std::isnan(s.source.horizontal_fov_angle)) s.source.horizontal_fov_angle = s.camera.intrinsics.hfov_rad();
  if (std::isnan(s.source.vertical_fov_angle)) s.source.vertical_fov_angle = s.camera.intrinsics.vfov_rad();
  s.filter.csnb.seed = s.seed;
  try {
    s.source.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(s.file + ": map.observation: " + e.what());
  }
  return s;
}

}  // namespace

Scenario parse_scenario(const std::string& yaml_text, const std::string& file_name, const std::string& base_dir) {
  YAML::Node node;
  try {
    node = YAML::Load(yaml_text);
  } catch (const YAML::ParserException& e) {
    throw std::invalid_argument(file_name + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  }
  return parse_root(YamlMap(node, file_name, ""), base_dir);
}

Scenario load_scenario(const std::string& path) {
  const YAML::Node node = load_yaml_file(path);
  return parse_root(YamlMap(node, path, ""), std::filesystem::path(path).parent_path().string());
}

std::string default_scenario_path() { return std::string(STVL_SOURCE_DIR) + "/scenarios/office_corridor.yaml"; }

void apply_overrides(Scenario& s, const ScenarioOverrides& o) {
  if (o.seed) s.seed = *o.seed, s.filter.csnb.seed = *o.seed;
  if (o.filter_type) s.filter.type = filter::parse_filter_type(*o.filter_type);
  if (o.device) s.filter.device = filter::parse_device(*o.device);
  if (o.memory) s.filter.memory = filter::parse_memory_mode(*o.memory);
  if (o.voxel_size_m) {
    s.map.voxel_size = *o.voxel_size_m;
    s.filter.voxel.voxel_size_m = *o.voxel_size_m;
    s.filter.csnb.voxel_size_m = *o.voxel_size_m;
    s.map.validate();
  }
  if (o.duration_s) {
    if (!(*o.duration_s > 0 && *o.duration_s <= 3600)) throw std::invalid_argument("--duration must be in (0, 3600] s");
    s.duration_s = *o.duration_s;
  }
  if (o.gl_backend) s.camera.gl_backend = sensors::parse_gl_backend(*o.gl_backend);
  if (o.noise) s.camera.noise.enabled = *o.noise;
}

}  // namespace stvl::tools

// A scenario's sensor sections: each camera's model, noise, edge filter, mount and outages, and the filter.
#include <algorithm>
#include <cmath>
#include <string>

#include "config/scenario_detail.hpp"

namespace stvl::config::scenario_detail {
namespace {

// The camera model: preset (or custom intrinsics), range and rate, validated together.
void read_camera_model(YamlMap& camera, pipeline::CameraConfig& c) {
  std::string preset = "d435_848x480";
  camera.get("preset", preset);
  std::optional<YamlMap> in;
  if (preset == "d435_848x480") {
    c.intrinsics = sensors::CameraIntrinsics::d435_848x480();
  } else if (preset == "d435_640x480") {
    c.intrinsics = sensors::CameraIntrinsics::d435_640x480();
  } else if (preset == "custom") {
    in = camera.map("intrinsics");
    in->require("width", c.intrinsics.width);
    in->require("height", c.intrinsics.height);
    in->require("fx", c.intrinsics.fx);
    in->require("fy", c.intrinsics.fy);
    in->require("cx", c.intrinsics.cx);
    in->require("cy", c.intrinsics.cy);
    in->finish();
  } else {
    camera.fail(camera.raw("preset"), "preset", "unknown preset '" + preset + "' (d435_848x480, d435_640x480, custom)");
  }
  if (!in && camera.has("intrinsics"))
    camera.fail(camera.raw("intrinsics"), "intrinsics", "only used with preset: custom (preset is " + preset + ")");
  camera.get("min_range_m", c.intrinsics.min_range_m);
  camera.get("max_range_m", c.intrinsics.max_range_m);
  camera.get("rate_hz", c.intrinsics.rate_hz);
  YamlMap& k = in ? *in : camera;
  const char* k_key = in ? "fx" : "preset";
  validate_keys({{k_key, &k, k_key},
                 {"width", &k, in ? "width" : "preset"},
                 {"height", &k, in ? "height" : "preset"},
                 {"fx", &k, k_key},
                 {"fy", &k, in ? "fy" : "preset"},
                 {"cx", &k, in ? "cx" : "preset"},
                 {"cy", &k, in ? "cy" : "preset"},
                 {"min_range_m", &camera, "min_range_m"},
                 {"max_range_m", &camera, "max_range_m"},
                 {"rate_hz", &camera, "rate_hz"}},
                [&] { c.intrinsics.validate(); });
}

void read_gl_backend(YamlMap& camera, pipeline::CameraConfig& c) {
  std::string backend = sensors::to_string(c.gl_backend);
  camera.get("gl_backend", backend);
  validate_keys({{"gl_backend", &camera, "gl_backend"}}, [&] { c.gl_backend = sensors::parse_gl_backend(backend); });
}

// camera.noise (sensors/depth_noise.hpp), when given.
void read_noise(YamlMap& camera, pipeline::CameraConfig& c) {
  if (!camera.has("noise")) return;
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
  noise.get("stereo_occlusion", n.stereo_occlusion);  // the bench's (real D435 artifacts), off by default
  noise.get("left_band_margin_px", n.left_band_margin_px);
  noise.get("left_band_jitter_px", n.left_band_jitter_px);
  noise.get("shadow_margin_px", n.shadow_margin_px);
  noise.get("correlated_fraction", n.correlated_fraction);  // the bench's, 0 = off
  noise.get("correlated_cell_px", n.correlated_cell_px);
  noise.finish();
  validate_keys({{"enabled", &noise, "enabled"},
                 {"baseline_m", &noise, "baseline_m"},
                 {"subpixel", &noise, "subpixel"},
                 {"disparity_step_px", &noise, "disparity_step_px"},
                 {"edge_jump_m", &noise, "edge_jump_m"},
                 {"edge_probability", &noise, "edge_probability"},
                 {"edge_invalid_fraction", &noise, "edge_invalid_fraction"},
                 {"dropout_probability", &noise, "dropout_probability"},
                 {"holes_per_frame", &noise, "holes_per_frame"},
                 {"hole_max_radius_px", &noise, "hole_max_radius_px"},
                 {"left_band_margin_px", &noise, "left_band_margin_px"},
                 {"left_band_jitter_px", &noise, "left_band_jitter_px"},
                 {"shadow_margin_px", &noise, "shadow_margin_px"},
                 {"correlated_fraction", &noise, "correlated_fraction"},
                 {"correlated_cell_px", &noise, "correlated_cell_px"}},
                [&] { n.validate(); });
}

// camera.edge_filter (the bench's: sensors/depth_edge_filter.hpp; STVL has none), when given.
void read_edge_filter(YamlMap& camera, pipeline::CameraConfig& c) {
  if (!camera.has("edge_filter")) return;
  auto edge = camera.map("edge_filter");
  edge.get("enabled", c.edge_filter.enabled);
  edge.get("max_jump_at_1m_m", c.edge_filter.max_jump_at_1m_m);
  edge.finish();
  validate_keys({{"max_jump_at_1m_m", &edge, "max_jump_at_1m_m"}}, [&] { c.edge_filter.validate(); });
}

// camera.timing (issue 43: sensors/camera_timing.hpp), when given.
void read_timing(YamlMap& camera, pipeline::CameraConfig& c) {
  if (!camera.has("timing")) return;
  auto timing = camera.map("timing");
  auto& t = c.timing;
  timing.get("latency_mean_s", t.latency_mean_s);
  timing.get("latency_jitter_s", t.latency_jitter_s);
  std::string stamp = sensors::to_string(t.stamp);
  timing.get("stamp", stamp);
  validate_keys({{"stamp", &timing, "stamp"}}, [&] { t.stamp = sensors::parse_stamp_mode(stamp); });
  timing.get("stamp_offset_s", t.stamp_offset_s);
  timing.get("drop_probability", t.drop_probability);
  timing.get("drop_burst_frames", t.drop_burst_frames);
  timing.finish();
  validate_keys({{"latency_mean_s", &timing, "latency_mean_s"},
                 {"latency_jitter_s", &timing, "latency_jitter_s"},
                 {"stamp_offset_s", &timing, "stamp_offset_s"},
                 {"drop_probability", &timing, "drop_probability"},
                 {"drop_burst_frames", &timing, "drop_burst_frames"}},
                [&] { t.validate(); });
}

}  // namespace

// The keys of a camera (top-level `camera` or an entry of robot.cameras) that describe the sensor itself.
void read_camera_sensor(YamlMap& camera, pipeline::CameraConfig& c) {
  read_camera_model(camera, c);
  read_gl_backend(camera, c);
  read_noise(camera, c);
  read_edge_filter(camera, c);
  read_timing(camera, c);
}

// A camera's outages: [{from_s, to_s}], each inside the run, from_s < to_s, none overlapping another.
void read_outages(YamlMap& camera, pipeline::CameraConfig& c, double duration_s) {
  c.outages.clear();
  for (auto& entry : camera.list_of_maps("outages")) {
    pipeline::Outage o;
    entry.require("from_s", o.from_s);
    entry.require("to_s", o.to_s);
    entry.finish();
    require_range(entry, "from_s", o.from_s, std::isfinite(o.from_s) && o.from_s >= 0.0, "must be finite and >= 0 s");
    require_range(entry, "to_s", o.to_s, std::isfinite(o.to_s) && o.to_s > o.from_s,
                  "must be finite and > from_s (" + std::to_string(o.from_s) + " s)");
    require_range(entry, "to_s", o.to_s, o.to_s <= duration_s,
                  "must be <= duration_s (" + std::to_string(duration_s) + " s): the outage must end inside the run");
    for (std::size_t i = 0; i < c.outages.size(); ++i)
      if (o.from_s < c.outages[i].to_s && c.outages[i].from_s < o.to_s)
        require_range(entry, "from_s", o.from_s, false,
                      "overlaps outages[" + std::to_string(i) + "] [" + std::to_string(c.outages[i].from_s) + ", " +
                          std::to_string(c.outages[i].to_s) + ") s");
    c.outages.push_back(o);
  }
  std::sort(c.outages.begin(), c.outages.end(),
            [](const pipeline::Outage& a, const pipeline::Outage& b) { return a.from_s < b.from_s; });
}

void read_camera(YamlMap camera, Scenario& s) {
  read_camera_sensor(camera, s.camera());
  read_outages(camera, s.camera(), s.duration_s);
  camera.finish();
}

void read_mount(YamlMap mount, sim::CameraMount& m) {
  std::vector<double> xyz{m.forward_offset_m, m.lateral_offset_m, m.height_m};
  double roll_deg = 0, pitch_deg = 0, yaw_deg = 0;
  mount.require("xyz_m", xyz);
  if (xyz.size() != 3) mount.fail(mount.raw("xyz_m"), "xyz_m", "expected [x, y, z] in metres on base_link");
  mount.get("roll_deg", roll_deg);
  mount.get("pitch_deg", pitch_deg);
  mount.get("yaw_deg", yaw_deg);
  mount.finish();
  for (const char* key : {"xyz_m", "roll_deg", "pitch_deg", "yaw_deg"}) {
    const bool finite = std::string(key) == "xyz_m" ? std::isfinite(xyz[0] + xyz[1] + xyz[2])
                                                    : std::isfinite(roll_deg + pitch_deg + yaw_deg);
    require_range(mount, key, "non-finite values", finite, "must be finite");
  }
  require_range(mount, "xyz_m", xyz[2], xyz[2] > 0, "z must be > 0 m (a camera below the floor sees nothing)");
  m = {xyz[2], pitch_deg * kRadPerDeg, xyz[0], xyz[1], roll_deg * kRadPerDeg, yaw_deg * kRadPerDeg};
}

// robot.cameras: each entry a camera with its name and mount; its observation overrides (applied once the map's
// observation defaults are known) stay in `overrides`.
void read_cameras(YamlMap& robot, Scenario& s, std::vector<std::optional<YamlMap>>& overrides) {
  auto entries = robot.list_of_maps("cameras");
  if (entries.empty()) robot.fail(robot.raw("cameras"), "cameras", "expected at least one camera");
  if (robot.has("camera_mount"))
    robot.fail(robot.raw("camera_mount"), "camera_mount", "give each camera its mount in robot.cameras instead");
  s.pipeline.cameras.clear();
  overrides.clear();
  for (auto& entry : entries) {
    pipeline::CameraConfig c;
    entry.require("name", c.name);
    require_range(entry, "name", "an empty name", !c.name.empty(), "must not be empty");
    for (const auto& other : s.pipeline.cameras)
      if (other.name == c.name) entry.fail(entry.raw("name"), "name", "two cameras are named '" + c.name + "'");
    if (entry.has("frame")) {
      s.camera_mount_locations.push_back(entry.where("frame"));
      read_camera_frame(entry, s, c);
    } else {
      s.camera_mount_locations.push_back(entry.where("mount"));
      read_mount(entry.map("mount"), c.mount);
    }
    read_camera_sensor(entry, c);
    read_outages(entry, c, s.duration_s);
    c.sources.front().name = c.name;
    overrides.push_back(entry.has("observation") ? std::optional<YamlMap>(entry.map("observation")) : std::nullopt);
    entry.finish();
    s.pipeline.cameras.push_back(std::move(c));
  }
}

void read_filter(YamlMap filter, Scenario& s) {
  auto& f = s.pipeline.filter;
  std::string type = filter::to_string(f.type), device = filter::to_string(f.device),
              memory = filter::to_string(f.memory);
  filter.get("type", type);
  filter.get("device", device);
  filter.get("memory", memory);
  validate_keys({{"type", &filter, "type"}}, [&] { f.type = filter::parse_filter_type(type); });
  validate_keys({{"device", &filter, "device"}}, [&] { f.device = filter::parse_device(device); });
  validate_keys({{"memory", &filter, "memory"}}, [&] { f.memory = filter::parse_memory_mode(memory); });
  filter.get("cpu_threads", f.cpu_threads);
  require_range(filter, "cpu_threads", f.cpu_threads, f.cpu_threads >= 0, "must be >= 0 (0: all cores)");
  if (filter.has("passthrough")) {
    auto p = filter.map("passthrough");
    p.get("enabled", f.passthrough_enabled);
    p.get("before_decimation", f.band_before_decimation);
    p.get("min_z_m", f.passthrough.min_z_m);
    p.get("max_z_m", f.passthrough.max_z_m);
    require_range(p, "min_z_m", f.passthrough.min_z_m,
                  !std::isnan(f.passthrough.min_z_m) && !std::isnan(f.passthrough.max_z_m) &&
                      f.passthrough.min_z_m <= f.passthrough.max_z_m,
                  "must be a number <= max_z_m (" + std::to_string(f.passthrough.max_z_m) + ")");
    p.finish();
  }
  if (filter.has("voxel")) {
    auto v = filter.map("voxel");
    v.get("voxel_size_m", f.voxel.voxel_size_m);
    v.get("min_points_per_voxel", f.voxel.min_points_per_voxel);
    require_range(v, "voxel_size_m", f.voxel.voxel_size_m,
                  std::isfinite(f.voxel.voxel_size_m) && f.voxel.voxel_size_m > 0, "must be finite and > 0 m");
    require_range(v, "min_points_per_voxel", f.voxel.min_points_per_voxel, f.voxel.min_points_per_voxel >= 0,
                  "must be >= 0");
    v.finish();
  }
  if (filter.has("csnb")) {
    auto c = filter.map("csnb");
    c.get("voxel_size_m", f.csnb.voxel_size_m);
    c.get("max_neighbours", f.csnb.max_neighbours);
    c.get("batch_size", f.csnb.batch_size);
    c.get("grid_exponent", f.csnb.grid_exponent);
    require_range(c, "voxel_size_m", f.csnb.voxel_size_m, std::isfinite(f.csnb.voxel_size_m) && f.csnb.voxel_size_m > 0,
                  "must be finite and > 0 m");
    require_range(c, "max_neighbours", f.csnb.max_neighbours, f.csnb.max_neighbours >= 0, "must be >= 0");
    require_range(c, "batch_size", f.csnb.batch_size, f.csnb.batch_size >= 1, "must be >= 1");
    require_range(c, "grid_exponent", f.csnb.grid_exponent,
                  f.csnb.grid_exponent == 0 || (f.csnb.grid_exponent >= 4 && f.csnb.grid_exponent <= 9),
                  "must be 0 (auto) or 4..9");
    c.finish();
  }
  filter.finish();
}

namespace {
// The key's text parsed into out when the key is given; the parser's message at the key otherwise.
template <class E>
void read_named(YamlMap& o, const char* key, E (*parse)(const std::string&), E& out) {
  if (!o.has(key)) return;
  std::string text;
  o.get(key, text);
  try {
    out = parse(text);
  } catch (const std::invalid_argument& e) {
    o.fail(o.raw(key), key, e.what());
  }
}
}  // namespace

// An observation's model_type (0 or 1), sensor_frame (optical | link) and z_reference_frame (global | base_link,
// STVL's relative filters), each only when given.
void read_clearing_model(YamlMap& o, mapping::ObservationSource& src) {
  if (o.has("model_type")) {
    int model = 0;
    o.get("model_type", model);
    if (model != 0 && model != 1)
      o.fail(o.raw("model_type"), "model_type", "STVL knows 0 (depth camera) and 1 (3D lidar)");
    src.model = static_cast<mapping::ClearingModel>(model);
  }
  read_named(o, "sensor_frame", &mapping::parse_sensor_frame, src.sensor_frame);
  read_named(o, "z_reference_frame", &mapping::parse_z_reference, src.z_reference);
}

// tf (issue 43): the robot's odometry transforms as they reach the tf buffer, and the layer's transform_tolerance
// (over map.ros_params' transform_tolerance).
void read_tf(YamlMap tf, Scenario& s) {
  layer::TfTimingConfig& t = s.pipeline.tf;
  tf.get("odom_rate_hz", t.odom_rate_hz);
  tf.get("odom_latency_s", t.odom_latency_s);
  tf.get("transform_tolerance", t.transform_tolerance_s);
  tf.finish();
  validate_keys({{"odom_rate_hz", &tf, "odom_rate_hz"},
                 {"odom_latency_s", &tf, "odom_latency_s"},
                 {"transform_tolerance", &tf, "transform_tolerance"}},
                [&] { t.validate(); });
}

// localization (issue 43: sim/localization.hpp): map -> odom as a localizer publishes it, with scripted jumps.
void read_localization(YamlMap loc, Scenario& s) {
  sim::LocalizationConfig& l = s.pipeline.sim.localization;
  l.enabled = true;
  loc.get("rate_hz", l.rate_hz);
  loc.get("noise_xy_m", l.noise_xy_m);
  loc.get("noise_yaw_rad", l.noise_yaw_rad);
  std::string frame = l.layer_in_odom ? "odom" : "map";
  loc.get("global_frame", frame);
  require_range(loc, "global_frame", frame, frame == "map" || frame == "odom",
                "must be map (the global costmap's frame) or odom (the local costmap's)");
  l.layer_in_odom = frame == "odom";
  l.jumps.clear();
  for (auto& entry : loc.list_of_maps("jumps")) {
    sim::LocalizationJump j;
    entry.require("at_s", j.at_s);
    entry.get("x_m", j.x_m);
    entry.get("y_m", j.y_m);
    entry.get("yaw_rad", j.yaw_rad);
    entry.finish();
    l.jumps.push_back(j);
    // The jump's own entry is blamed for its values (the message names jumps[i] and its key).
    validate_keys(
        {{"at_s", &entry, "at_s"}, {"x_m", &entry, "x_m"}, {"y_m", &entry, "y_m"}, {"yaw_rad", &entry, "yaw_rad"}},
        [&] {
          sim::LocalizationConfig so_far;
          so_far.jumps = l.jumps;
          so_far.validate(s.duration_s);
        });
  }
  loc.finish();
  validate_keys(
      {{"rate_hz", &loc, "rate_hz"}, {"noise_xy_m", &loc, "noise_xy_m"}, {"noise_yaw_rad", &loc, "noise_yaw_rad"}},
      [&] { l.validate(s.duration_s); });
}

}  // namespace stvl::config::scenario_detail

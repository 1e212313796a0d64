#include "config/ros_lint.hpp"

#include <algorithm>
#include <cmath>
#include <regex>

#include "common/enum_names.hpp"
#include "common/format.hpp"
#include "common/units.hpp"
#include "config/ros_lint_geometry.hpp"
#include "config/ros_params_detail.hpp"
#include "config/stvl_keys.hpp"

namespace stvl::config {
namespace {

using ros_detail::dotted;
using ros_detail::key_line;
namespace geo = lint_geometry;

constexpr double kFovTolerance = 0.05;  // relative

// Rounded to the centimetre, down or up (a suggestion that is safe on its side).
double cm_down(double m) { return std::floor(m * 100.0 + 1e-6) / 100.0; }
double cm_up(double m) { return std::ceil(m * 100.0 - 1e-6) / 100.0; }
std::string cm(double m) { return general(std::round(m * 100.0) / 100.0); }

bool contains(const std::vector<std::string>& keys, const std::string& key) {
  return std::find(keys.begin(), keys.end(), key) != keys.end();
}

class Linter {
 public:
  explicit Linter(const ros_detail::ReadLayer& read) : layer_(read.layer), nodes_(read.nodes) {}

  void add(int line, const std::string& key, const std::string& what, const std::string& instead) {
    findings_.push_back({layer_.file, line, key, what, instead});
  }
  // Line of `key` in `map` when written, else `fallback`.
  static int line_or(const YAML::Node& map, const std::string& key, int fallback) {
    const int line = key_line(map, key);
    return line > 0 ? line : fallback;
  }
  std::string version() const { return nodes_.flavour == RosFlavour::kRos1 ? "STVL (ROS 1)" : "STVL (ROS 2)"; }

  void layer_keys() {
    std::vector<std::string> sources;
    for (const auto& s : layer_.sources) sources.push_back(s.name);
    const auto& known = ros_detail::layer_keys(nodes_.flavour);
    for (const auto& entry : nodes_.layer) {
      const std::string k = entry.first.Scalar();
      if (contains(known, k) || contains(sources, k)) continue;
      const int line = key_line(nodes_.layer, k);
      const std::string key = dotted(nodes_.layer_path, k);
      if (k == "unknown_threshold" || k == "origin_z") {
        add(line, key, version() + " does not read " + k + " (a voxel_layer key); it has no effect", "remove it");
      } else if (k == "obstacle_range" || k == "max_obstacle_height" || k == "min_obstacle_height") {
        const char* fallback = k == "obstacle_range" ? "2.5" : k == "max_obstacle_height" ? "3.0" : "0.0";
        add(line, key,
            version() + " reads " + k + " per source only; this layer-level value has no effect (a source without " +
                "its own uses " + fallback + " m)",
            k + ": " + entry.second.as<std::string>("") + " under each source");
      } else if (entry.second.IsMap()) {
        add(line, key, "a mapping not named in observation_sources: STVL does not read it",
            "add " + k + " to observation_sources, or remove it");
      } else {
        unknown(line, key, k, known);
      }
    }
  }

  void source_keys(const RosObservationSource& s) {
    const YAML::Node node = nodes_.layer[s.name];
    const auto& known = ros_detail::source_keys(nodes_.flavour);
    const std::string prefix = dotted(nodes_.layer_path, s.name);
    for (const auto& entry : node) {
      const std::string k = entry.first.Scalar();
      const int line = key_line(node, k);
      const bool voxel = entry.second.IsScalar() && entry.second.as<bool>(false);
      const std::string filter = voxel ? "filter: \"voxel\"" : "filter: \"passthrough\"";
      if (k == "voxel_filter" && nodes_.flavour != RosFlavour::kRos1) {
        add(line, dotted(prefix, k),
            "ROS 2 STVL ignores voxel_filter (ROS 1 melodic's key) and applies `filter` (default passthrough); "
            "voxel_filter: true silently has no effect (STVL issue #188: CPU use exploded)",
            filter);
      } else if (k == "voxel_filter" && !node["filter"]) {
        add(line, dotted(prefix, k),
            "melodic-devel reads voxel_filter, noetic-devel ignores it and applies `filter` (default passthrough)",
            "also " + filter + " for noetic");
      } else if (!contains(known, k)) {
        unknown(line, dotted(prefix, k), k, known);
      }
    }
  }

  // rclcpp types a parameter by STVL's default; an integer where a double is declared fails to load.
  void integer_doubles(const YAML::Node& map, const std::string& prefix, const std::vector<std::string>& keys) {
    if (nodes_.flavour != RosFlavour::kRos2) return;
    static const std::regex integer("[-+]?[0-9]+");
    for (const auto& k : keys) {
      const YAML::Node value = map[k];
      if (!value || !value.IsScalar() || !std::regex_match(value.Scalar(), integer)) continue;
      add(key_line(map, k), dotted(prefix, k),
          "STVL declares " + k + " a double and rclcpp (Galactic and later) rejects the integer " + value.Scalar() +
              ": the layer fails to load",
          k + ": " + value.Scalar() + ".0");
    }
  }

  void layer_values() {
    const YAML::Node& n = nodes_.layer;
    const int fallback = nodes_.layer_line;
    integer_doubles(n, nodes_.layer_path, stvl_double_key_names(StvlScope::kLayer, kReadByRos2));
    const int code = layer_.decay_model_code;
    if (code != 0 && code != 1)
      add(line_or(n, "decay_model", fallback), dotted(nodes_.layer_path, "decay_model"),
          "STVL treats decay_model " + std::to_string(code) +
              " as persistent (every code but 0 and 1): voxels never expire, only frustum acceleration removes them",
          "decay_model: 0 (linear) or 1 (exponential) for voxels to expire; -1, as STVL's README documents, if "
          "persistence is meant");
    if (layer_.map.voxel_decay_s < 0.0)
      add(line_or(n, "voxel_decay", fallback), dotted(nodes_.layer_path, "voxel_decay"),
          "voxel_decay = " + general(layer_.map.voxel_decay_s) + (n["voxel_decay"] ? "" : " (STVL's default)") +
              ": every voxel is removed at the next update, before the costmap is built, so the layer never marks a "
              "cell",
          "voxel_decay: 15.0 (STVL's example)");
    if (layer_.resolution_m && std::abs(*layer_.resolution_m - layer_.map.voxel_size_m) > kLengthEpsilon_m)
      add(line_or(n, "voxel_size", fallback), dotted(nodes_.layer_path, "voxel_size"),
          "voxel_size = " + general(layer_.map.voxel_size_m) + " m differs from the costmap's resolution = " +
              general(*layer_.resolution_m) + " m: STVL projects voxel columns onto cells of another size",
          "voxel_size: " + general(*layer_.resolution_m));
    const bool any_clearing = std::any_of(layer_.sources.begin(), layer_.sources.end(),
                                          [](const RosObservationSource& s) { return s.stvl.clearing; });
    if (!any_clearing)
      add(line_or(n, "observation_sources", fallback), dotted(nodes_.layer_path, "observation_sources"),
          "no source has clearing: true (STVL's default is false): voxels leave only by voxel_decay",
          "clearing: true on the depth camera's source");
  }

  void source_values(const RosObservationSource& s, const std::vector<BoundCamera>& cameras) {
    const YAML::Node node = nodes_.layer[s.name];
    const std::string prefix = dotted(nodes_.layer_path, s.name);
    const auto& v = s.stvl;
    integer_doubles(node, prefix, stvl_double_key_names(StvlScope::kSource, kReadByRos2));
    if (s.filter == RosSourceFilter::kNone && !s.filter_text.empty() && s.filter_text != "none")
      add(line_or(node, "filter", s.line), dotted(prefix, "filter"),
          "filter = '" + s.filter_text +
              "': STVL (ros2 403d9ed, noetic-devel 5e06daf) knows passthrough and voxel; any "
              "other string applies no filter, so no height band and every height marks (passthrough_relative and "
              "voxel_relative are the ros2 branch's, PR #304; noetic-devel does not know them)",
          "filter: passthrough (or voxel)");
    if (!s.filter_relative && node && node.IsMap() && node["z_reference_frame"])
      add(line_or(node, "z_reference_frame", s.line), dotted(prefix, "z_reference_frame"),
          "z_reference_frame = '" + s.z_reference_frame + "' has no effect with filter '" + s.filter_text +
              "': only passthrough_relative and voxel_relative read it (the band stays in the global frame's z)",
          "filter: passthrough_relative (or voxel_relative), or drop z_reference_frame");
    if (v.marking && v.min_obstacle_height_m <= 0.0)
      add(line_or(node, "min_obstacle_height", s.line), dotted(prefix, "min_obstacle_height"),
          "min_obstacle_height = " + general(v.min_obstacle_height_m) +
              " m: STVL marks points at floor level, so the depth camera's floor noise becomes obstacles",
          "min_obstacle_height: 0.05 (above the floor noise)");
    if (v.clearing && v.decay_acceleration_per_s3 == 0.0)
      add(line_or(node, "decay_acceleration", s.line), dotted(prefix, "decay_acceleration"),
          "decay_acceleration = 0 on a clearing source: the frustum does not speed up decay, only voxel_decay clears",
          "decay_acceleration: 15.0 (STVL's example)");
    const bool optical = s.sensor_frame.empty() || s.sensor_frame.find("optical") != std::string::npos;
    if (v.clearing && v.model == mapping::ClearingModel::kLidar3D && optical)
      add(line_or(node, "model_type", s.line), dotted(prefix, "model_type"),
          "model_type = 1 builds STVL's 3D lidar model (x forward, z up) in " +
              (s.sensor_frame.empty() ? std::string("the cloud's frame") : "'" + s.sensor_frame + "'") +
              ": a depth camera's optical frame looks along z, so the model's horizontal plane is the image plane "
              "and it clears beside the camera's view, not in it",
          "sensor_frame: <camera>_link (x forward, z up), or model_type: 0");
    if (v.clearing && v.model == mapping::ClearingModel::kDepthCamera && !optical)
      add(line_or(node, "sensor_frame", s.line), dotted(prefix, "sensor_frame"),
          "sensor_frame = '" + s.sensor_frame +
              "': STVL builds the depth camera's frustum along that frame's z axis, "
              "and by its name it is not an optical frame (z forward): with x forward and z up (a camera link) "
              "the frustum looks at the ceiling",
          "sensor_frame: <camera>_depth_optical_frame, or leave it empty (the cloud's frame)");
    for (const auto& camera : cameras) {
      // The FOV shapes the depth camera's clearing frustum only (the lidar model's is its own).
      if (camera.source != s.name || !v.clearing || v.model != mapping::ClearingModel::kDepthCamera) continue;
      fov(node, s, prefix, "horizontal_fov_angle", v.horizontal_fov_rad, camera.hfov_rad);
      fov(node, s, prefix, "vertical_fov_angle", v.vertical_fov_rad, camera.vfov_rad);
    }
  }

  // Across the enabled sources of each camera: marking beyond every clearing frustum's far plane, and heights
  // marked that no clearing frustum of the camera ever contains.
  void camera_sources(const std::vector<BoundCamera>& cameras) {
    for (const auto& m : layer_.sources) {
      if (!m.enabled || !m.stvl.marking) continue;
      std::vector<const RosObservationSource*> clearing;
      for (const auto& c : layer_.sources)  // the depth camera's frustum (the lidar model's geometry is its own)
        if (c.enabled && c.stvl.clearing && c.stvl.model == mapping::ClearingModel::kDepthCamera &&
            camera_key(c, cameras) == camera_key(m, cameras))
          clearing.push_back(&c);
      if (clearing.empty()) continue;
      marks_past_far_plane(m, clearing);
      const BoundCamera* camera = bound(m, cameras);
      if (camera && camera->height_m > 0.0 && camera->hfov_rad > 0.0 && camera->vfov_rad > 0.0)
        heights_never_cleared(m, clearing, *camera);
    }
  }

  std::vector<LintFinding> take() {
    std::stable_sort(findings_.begin(), findings_.end(),
                     [](const LintFinding& a, const LintFinding& b) { return a.line < b.line; });
    return std::move(findings_);
  }

 private:
  void unknown(int line, const std::string& key, const std::string& k, const std::vector<std::string>& known) {
    const std::string nearest = nearest_name(k, known);
    add(line, key, version() + " does not read " + k + "; it has no effect",
        nearest.empty() ? "remove it" : nearest + " (the nearest key STVL reads)");
  }
  static const BoundCamera* bound(const RosObservationSource& s, const std::vector<BoundCamera>& cameras) {
    for (const auto& c : cameras)
      if (c.source == s.name) return &c;
    return nullptr;
  }
  // Sources with the same key feed one camera: the bound camera's name, else the topic, else the sensor_frame.
  static std::string camera_key(const RosObservationSource& s, const std::vector<BoundCamera>& cameras) {
    const BoundCamera* c = bound(s, cameras);
    if (c && !c->camera.empty()) return "camera " + c->camera;
    const std::string topic = !s.topic.empty() && s.topic.front() == '/' ? s.topic.substr(1) : s.topic;
    if (!topic.empty()) return "topic " + topic;
    return s.sensor_frame.empty() ? "source " + s.name : "frame " + s.sensor_frame;
  }
  std::string where(const RosObservationSource& s) const { return s.name + " (line " + std::to_string(s.line) + ")"; }

  // STVL's far plane sits at max_z cos(h/2) cos(v/2) along the optical axis; a marking source whose obstacle_range
  // reaches past every clearing frustum of its camera leaves voxels frustum acceleration never reaches.
  void marks_past_far_plane(const RosObservationSource& m, const std::vector<const RosObservationSource*>& clearing) {
    const RosObservationSource* best = nullptr;
    double far = 0.0;
    for (const auto* c : clearing) {
      const double f = geo::stvl_plane_depth(c->stvl.max_z_m, c->stvl.horizontal_fov_rad, c->stvl.vertical_fov_rad);
      if (!best || f > far + 1e-12 || (c == &m && f >= far - 1e-12)) best = c, far = f;
    }
    const double range = m.stvl.obstacle_range_m;
    if (!(range > far + kLengthEpsilon_m)) return;
    const auto& b = best->stvl;
    const std::string plane =
        "STVL's depth-camera frustum puts its far plane at max_z·cos(h/2)·cos(v/2) = " + general(b.max_z_m) +
        " × cos(" + general(b.horizontal_fov_rad / 2.0) + ") × cos(" + general(b.vertical_fov_rad / 2.0) +
        ") = " + cm(far) + " m along the optical axis, not at max_z";
    const std::string beyond =
        ": voxels marked between " + cm(far) + " and " + general(range) +
        " m are never reached by frustum acceleration (decay_acceleration), only voxel_decay removes them";
    const std::string raise =
        "max_z: " + general(cm_up(geo::stvl_radial_for_depth(range, b.horizontal_fov_rad, b.vertical_fov_rad)));
    const YAML::Node node = nodes_.layer[m.name];
    const std::string prefix = dotted(nodes_.layer_path, m.name);
    if (best == &m)
      add(line_or(node, "max_z", m.line), dotted(prefix, "max_z"),
          "max_z = " + general(b.max_z_m) + " m with obstacle_range = " + general(range) + " m: " + plane + beyond,
          raise + " (obstacle_range / (cos(h/2)·cos(v/2))), or obstacle_range: " + general(cm_down(far)));
    else
      add(line_or(node, "obstacle_range", m.line), dotted(prefix, "obstacle_range"),
          "obstacle_range = " + general(range) + " m marks past the clearing frustum of " + where(*best) +
              ", the same camera's source reaching farthest: " + plane + beyond,
          raise + " on " + best->name +
              " (obstacle_range / (cos(h/2)·cos(v/2))), or obstacle_range: " + general(cm_down(far)));
  }

  // Heights (world z) the camera marks within obstacle_range that no clearing frustum of it contains at any
  // distance: the robot drives on a flat floor, so a voxel's height relative to the camera never changes.
  void heights_never_cleared(const RosObservationSource& m, const std::vector<const RosObservationSource*>& clearing,
                             const BoundCamera& camera) {
    const geo::CameraHeight pose{camera.height_m, camera.pitch_rad, camera.roll_rad};
    const double range =
        camera.max_range_m > 0.0 ? std::min(m.stvl.obstacle_range_m, camera.max_range_m) : m.stvl.obstacle_range_m;
    geo::HeightRange marked = geo::view_heights(pose, camera.hfov_rad, camera.vfov_rad, range);
    marked.min_m = std::max(marked.min_m, 0.0);            // nothing below the floor
    const bool band = m.filter != RosSourceFilter::kNone;  // filter none applies no height band (STVL's buffer)
    if (band) {
      marked.min_m = std::max(marked.min_m, m.stvl.min_obstacle_height_m);
      marked.max_m = std::min(marked.max_m, m.stvl.max_obstacle_height_m);
    }
    if (!(marked.max_m > marked.min_m)) return;
    std::vector<geo::HeightRange> frustums;
    std::string names;
    for (const auto* c : clearing) {
      frustums.push_back(geo::stvl_frustum_heights(pose, c->stvl.min_z_m, c->stvl.max_z_m, c->stvl.horizontal_fov_rad,
                                                   c->stvl.vertical_fov_rad));
      names += (names.empty() ? "" : ", ") + c->name + " z " + cm(frustums.back().min_m) + ".." +
               cm(frustums.back().max_m) + " m";
    }
    const auto left = geo::uncovered(marked, frustums, layer_.map.voxel_size_m);
    if (left.empty()) return;
    double top = frustums[0].max_m, bottom = frustums[0].min_m;
    for (const auto& f : frustums) top = std::max(top, f.max_m), bottom = std::min(bottom, f.min_m);
    std::string heights;
    for (const auto& r : left) heights += (heights.empty() ? "" : " and ") + cm(r.min_m) + ".." + cm(r.max_m);
    const bool above = left.back().max_m > top;
    const std::string k = above ? "max_obstacle_height" : "min_obstacle_height";
    const std::string value = general(above ? cm_down(top) : cm_up(bottom));
    add(line_or(nodes_.layer[m.name], k, m.line), dotted(dotted(nodes_.layer_path, m.name), k),
        "heights " + heights + " m (world z) are marked but never cleared: camera " + camera.camera + " (" +
            cm(camera.height_m) + " m above the floor, pitch " + cm(degrees(camera.pitch_rad)) +
            " deg) sees them within obstacle_range = " + general(m.stvl.obstacle_range_m) +
            " m, and no clearing frustum of it (STVL's: " + names +
            ") contains them at any distance or robot pose: those voxels leave only by voxel_decay",
        (band ? "" : "filter: \"passthrough\" with ") + k + ": " + value + ", or widen the clearing source's " +
            "vertical_fov_angle / raise its max_z");
  }

  void fov(const YAML::Node& node, const RosObservationSource& s, const std::string& prefix, const std::string& k,
           double written_rad, double real_rad) {
    if (!(real_rad > 0.0) || std::abs(written_rad - real_rad) <= kFovTolerance * real_rad) return;
    add(line_or(node, k, s.line), dotted(prefix, k),
        k + " = " + general(written_rad) + " rad is more than 5 % off the bound camera's " + general(real_rad) +
            " rad: STVL's clearing frustum " +
            (written_rad > real_rad ? "clears voxels the camera cannot see" : "leaves the edges of the view uncleared"),
        k + ": " + general(real_rad));
  }

  const RosStvlLayer& layer_;
  const ros_detail::LayerNodes& nodes_;
  std::vector<LintFinding> findings_;
};

}  // namespace

std::vector<LintFinding> lint_ros_stvl_layer(const std::string& path, const std::string& layer,
                                             const std::string& costmap, const std::vector<BoundCamera>& cameras) {
  const ros_detail::ReadLayer read = ros_detail::read_layer(path, layer, costmap, true);
  Linter linter(read);
  linter.layer_keys();
  linter.layer_values();
  for (const auto& s : read.layer.sources) {
    linter.source_keys(s);
    linter.source_values(s, cameras);
  }
  linter.camera_sources(cameras);
  return linter.take();
}

std::string format_finding(const LintFinding& f) {
  return f.file + (f.line > 0 ? ":" + std::to_string(f.line) : "") + ": " + f.key + ": " + f.what_stvl_does +
         "; write instead: " + f.write_instead;
}

}  // namespace stvl::config

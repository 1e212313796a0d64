#pragma once
// Shared by scenario.cpp and scenario_sensors.cpp (not a public header): the reader's helpers that blame a file,
// line and key, and the sections scenario_sensors.cpp reads.
#include <cctype>
#include <cmath>
#include <initializer_list>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "common/format.hpp"
#include "common/units.hpp"
#include "config/scenario.hpp"
#include "config/yaml_reader.hpp"

namespace stvl::worldgen {
struct MapWorld;
}

namespace stvl::config::scenario_detail {

// A field a module's validate() may name in its message, and the YAML key (in `map`) that sets it.
struct Blame {
  const char* word;
  YamlMap* map;
  const char* key;
};

inline std::size_t find_word(const std::string& text, const std::string& word) {
  const auto is_name_char = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (auto pos = text.find(word); pos != std::string::npos; pos = text.find(word, pos + 1)) {
    const bool starts = pos == 0 || !is_name_char(text[pos - 1]);
    const bool ends = pos + word.size() == text.size() || !is_name_char(text[pos + word.size()]);
    if (starts && ends) return pos;
  }
  return std::string::npos;
}

// Runs a module's validation; its std::invalid_argument is rethrown naming the file, line and key of the field
// mentioned first in the message (the first entry of `blame` when none is).
template <typename F>
void validate_keys(const std::vector<Blame>& blame, F&& validate) {
  try {
    validate();
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    const Blame* culprit = &blame.front();
    std::size_t first = std::string::npos;
    for (const auto& b : blame) {
      const std::size_t pos = find_word(message, b.word);
      if (pos < first) first = pos, culprit = &b;
    }
    YamlMap& map = *culprit->map;
    map.fail(map.has(culprit->key) ? map.raw(culprit->key) : YAML::Node(), culprit->key, message);
  }
}

template <typename T>
void require_range(YamlMap& map, const std::string& key, const T& value, bool ok, const std::string& rule) {
  if (ok) return;
  std::ostringstream text;
  text << rule << ", got " << value;
  map.fail(map.has(key) ? map.raw(key) : YAML::Node(), key, text.str());
}

template <typename T>
void get_optional(YamlMap& map, const std::string& key, std::optional<T>& value) {
  if (!map.has(key)) return;
  T v{};
  map.get(key, v);
  value = v;
}

inline Eigen::Vector2d to_point2(const std::vector<double>& xy, YamlMap& map, const std::string& key) {
  if (xy.size() != 2) map.fail(map.raw(key), key, "expected [x, y] points");
  return {xy[0], xy[1]};
}

// scenario_sensors.cpp: a camera's sensor keys (preset, intrinsics, range, rate, GL, noise, edge filter), its
// outages, the top-level `camera`, robot.cameras (their observation overrides kept in `overrides`), `filter`.
void read_camera_sensor(YamlMap& camera, pipeline::CameraConfig& c);
// tf: odometry's rate and latency on tf and the layer's transform_tolerance (issue 43).
void read_tf(YamlMap tf, Scenario& s);
void read_localization(YamlMap localization, Scenario& s);
void read_outages(YamlMap& camera, pipeline::CameraConfig& c, double duration_s);
void read_camera(YamlMap camera, Scenario& s);
void read_cameras(YamlMap& robot, Scenario& s, std::vector<std::optional<YamlMap>>& overrides);
void read_filter(YamlMap filter, Scenario& s);
// An observation's model_type and sensor_frame (STVL's clearing model and the frame it is built in).
void read_clearing_model(YamlMap& observation, mapping::ObservationSource& src);

// scenario_evaluation.cpp: the `evaluation` section (its cadence, windows and tolerances) and the `checks`
// section (each check's threshold), into s.evaluation and s.checks.
void read_evaluation(YamlMap e, Scenario& s);
void read_checks(YamlMap c, Scenario& s);
// scenario_navigation.cpp: whether navigation.mode is closed_loop (read before the robot, whose waypoints it makes
// optional), and the navigation section (the goal defaults to the last of waypoints_W).
bool navigation_closed_loop(YamlMap& root);
// map_world: the nav2 map the world was built from (null for an MJCF world): the goal must lie on a free cell of it.
void read_navigation(YamlMap n, Scenario& s, const std::vector<Eigen::Vector2d>& waypoints_W,
                     const std::string& base_dir, const worldgen::MapWorld* map_world);

// scenario_robot.cpp: robot.urdf with package_path, wheels and drive (the robot built, sim.robot and sim.drive set
// from it; without urdf those keys are errors); a camera's `frame` (a URDF link) as its mount; the URDF's
// footprint where the scenario and its ROS file give none.
void read_urdf_robot(YamlMap& robot, Scenario& s, const std::string& base_dir);
void read_camera_frame(YamlMap& camera, const Scenario& s, pipeline::CameraConfig& c);
void complete_footprint(Scenario& s);
// scenario_map.cpp: `nav2_map` (instead of `world`): the world built in memory from a nav2 map (worldgen/), and the
// path planned on it when robot.waypoints is left out.
// map.nav2_costmap (scenario_map.cpp): nav2's master costmap to model.
void read_nav2_costmap(YamlMap costmap, Scenario& s);
// map.layer_type and, for nav2's layers, map.nav2_layer (nav2's layer keys under their nav2 names).
void read_layer_type(YamlMap& map, Scenario& s);
// A source's nav2 ranges (obstacle_max_range, obstacle_min_range, raytrace_max_range, raytrace_min_range): finite
// and >= 0 m.
void read_nav2_ranges(YamlMap& o, layer::Nav2SourceRanges& nav2);
std::shared_ptr<const worldgen::MapWorld> read_nav2_map(YamlMap map, Scenario& s, const std::string& base_dir);
// robot.waypoints planned on the map for the robot's footprint radius (a URDF robot's when robot.urdf was read, else
// worlds/robot.xml's), from robot.start when the file gives one (read already), else along the map's longest path,
// which sets the start pose too.
void plan_on_map(const worldgen::MapWorld& world, YamlMap& robot, Scenario& s);
// The duration a planned drive needs (worldgen's scenario writer's); throws naming robot.waypoints above 3600 s.
double planned_duration_s(YamlMap& robot, const Scenario& s);

}  // namespace stvl::config::scenario_detail

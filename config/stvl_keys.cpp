#include "config/stvl_keys.hpp"

#include <algorithm>

namespace stvl::config {
namespace {

using Src = mapping::ObservationSource;
constexpr unsigned kRos = kReadByRos2 | kReadByNoetic | kReadByMelodic;
constexpr unsigned kAll = kRos | kReadByScenario;

// Defaults are those STVL's code declares (spatio_temporal_voxel_layer.cpp onInitialize(), ros2 and noetic-devel);
// the bench's own defaults (mapping/config.hpp) apply to scenarios.
StvlKey layer(const char* name, unsigned by, const char* unit, const char* ros2, const char* ros1) {
  return {name, StvlScope::kLayer, by, unit, ros2, ros1};
}
StvlKey number(const char* name, unsigned by, const char* unit, const char* ros2, const char* ros1,
               double Src::*field) {
  return {name, StvlScope::kSource, by, unit, ros2, ros1, field, nullptr};
}
StvlKey flag(const char* name, unsigned by, const char* ros2, const char* ros1, bool Src::*field) {
  return {name, StvlScope::kSource, by, "", ros2, ros1, nullptr, field};
}
StvlKey other(const char* name, unsigned by, const char* unit, const char* ros2, const char* ros1) {
  return {name, StvlScope::kSource, by, unit, ros2, ros1};
}

}  // namespace

const std::vector<StvlKey>& stvl_keys() {
  static const std::vector<StvlKey> table = {
      layer("plugin", kReadByRos2, "", "", ""),  // nav2's plugin type (ROS 1 lists plugins as {name, type})
      layer("observation_sources", kRos, "", "\"\"", "\"\""),
      layer("transform_tolerance", kRos, "s", "0.2", "0.2"),
      layer("enabled", kRos, "", "true", "true"),
      layer("publish_voxel_map", kRos, "", "false", "false"),
      layer("voxel_size", kRos, "m", "0.05", "0.05"),
      layer("combination_method", kRos, "", "1", "1"),
      layer("mark_threshold", kRos, "", "0", "0"),
      layer("update_footprint_enabled", kRos, "", "true", "true"),
      layer("track_unknown_space", kRos, "", "costmap's", "costmap's"),
      layer("decay_model", kRos, "", "0", "0"),
      layer("voxel_decay", kRos, "s", "-1.0", "-1.0"),
      layer("mapping_mode", kRos, "", "false", "false"),
      layer("map_save_duration", kRos, "s", "60.0", "60.0"),
      layer("obstacle_range", kReadByNoetic | kReadByMelodic, "m", "", "3.0"),  // ROS 1's searchParam()

      other("topic", kRos, "", "\"\"", "source name"),
      other("sensor_frame", kAll, "", "\"\"", "\"\""),  // scenarios: optical | link
      number("observation_persistence", kAll, "s", "0.0", "0.0", &Src::observation_persistence_s),
      number("expected_update_rate", kAll, "s", "0.0", "0.0", &Src::expected_update_rate_s),
      other("data_type", kRos, "", "PointCloud2", "PointCloud2"),
      number("min_obstacle_height", kAll, "m", "0.0", "0.0", &Src::min_obstacle_height_m),
      number("max_obstacle_height", kAll, "m", "3.0", "3.0", &Src::max_obstacle_height_m),
      other("inf_is_valid", kRos, "", "false", "false"),
      flag("marking", kAll, "true", "true", &Src::marking),
      flag("clearing", kAll, "false", "false", &Src::clearing),
      number("obstacle_range", kAll, "m", "2.5", "3.0", &Src::obstacle_range_m),
      number("min_z", kAll, "m", "0.0", "0.0", &Src::min_z_m),
      number("max_z", kAll, "m", "10.0", "10.0", &Src::max_z_m),
      number("vertical_fov_angle", kAll, "rad", "0.7", "0.7", &Src::vertical_fov_rad),
      number("vertical_fov_padding", kAll, "m", "0.0", "0.0", &Src::vertical_fov_padding_m),
      number("horizontal_fov_angle", kAll, "rad", "1.04", "1.04", &Src::horizontal_fov_rad),
      number("decay_acceleration", kAll, "1/s^3", "0.0", "0.0", &Src::decay_acceleration_per_s3),
      other("filter", kReadByRos2 | kReadByNoetic, "", "passthrough", "passthrough"),
      other("voxel_filter", kReadByMelodic, "", "", "false"),
      // The ros2 branch's relative filters (PR #304 as 22f7927); scenarios: global | base_link.
      other("z_reference_frame", kReadByRos2 | kReadByScenario, "", "global frame", ""),
      other("voxel_min_points", kRos, "", "0", "0"),
      other("clear_after_reading", kRos, "", "false", "false"),
      other("enabled", kRos, "", "true", "true"),
      other("model_type", kAll, "", "0", "0"),
      // The bench's own (no STVL branch reads them): scenario files only.
      flag("clear_on_no_return", kReadByScenario, "", "", &Src::clear_on_no_return),
      flag("drop_when_not_current", kReadByScenario, "", "", &Src::drop_when_not_current),
  };
  return table;
}

std::vector<std::string> stvl_key_names(StvlScope scope, unsigned readers) {
  std::vector<std::string> names;
  for (const StvlKey& k : stvl_keys())
    if (k.scope == scope && (k.read_by & readers)) names.emplace_back(k.name);
  return names;
}

std::vector<std::string> stvl_double_key_names(StvlScope scope, unsigned readers) {
  std::vector<std::string> names;
  for (const StvlKey& k : stvl_keys())
    if (k.scope == scope && (k.read_by & readers) && k.is_double()) names.emplace_back(k.name);
  return names;
}

void read_source_keys(YamlMap& map, mapping::ObservationSource& source, unsigned reader,
                      const std::vector<std::string>& skip) {
  for (const StvlKey& k : stvl_keys()) {
    if (k.scope != StvlScope::kSource || !(k.read_by & reader)) continue;
    if (std::find(skip.begin(), skip.end(), k.name) != skip.end()) continue;
    if (k.number) map.get(k.name, source.*k.number);
    if (k.flag) map.get(k.name, source.*k.flag);
  }
}

}  // namespace stvl::config

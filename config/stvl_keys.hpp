#pragma once
// The one table of STVL's parameters: every key STVL's layer or its observation sources read, the bench field it
// sets, its unit, STVL's default per branch, and which readers take it (the scenario's map.observation, the ROS
// parameter reader and its locator, lint). A new STVL key is one row here.
#include <string>
#include <vector>

#include "config/yaml_reader.hpp"
#include "mapping/config.hpp"

namespace stvl::config {

// Who reads a key (bits).
enum StvlReader : unsigned {
  kReadByRos2 = 1u << 0,      // STVL's ros2 branch (nav2 parameter files, bare layer files)
  kReadByNoetic = 1u << 1,    // noetic-devel (move_base files)
  kReadByMelodic = 1u << 2,   // melodic-devel (voxel_filter instead of filter)
  kReadByScenario = 1u << 3,  // a scenario's map.observation / robot.cameras[i].observation (same YAML name)
};
enum class StvlScope { kLayer, kSource };

struct StvlKey {
  const char* name;  // the YAML key, as STVL and the scenario write it
  StvlScope scope;
  unsigned read_by;          // StvlReader bits
  const char* unit;          // "m", "s", "rad", "1/s^3", "" (flags, counts, names)
  const char* default_ros2;  // STVL's declared default on the ros2 branch ("" none / not read)
  const char* default_ros1;  // on noetic-devel ("" none / not read)
  // The bench's source field it sets, when it is a plain number or flag of mapping::ObservationSource (null
  // otherwise: layer keys, FOVs a scenario takes from the camera, names).
  double mapping::ObservationSource::*number = nullptr;
  bool mapping::ObservationSource::*flag = nullptr;

  bool is_double() const { return unit[0] != '\0'; }  // STVL declares it a double (a number with a unit)
};

// Every row, layer keys first, then source keys, each group in STVL's onInitialize() order.
const std::vector<StvlKey>& stvl_keys();

// The names of the keys in `scope` that any reader in `readers` takes, in table order.
std::vector<std::string> stvl_key_names(StvlScope scope, unsigned readers);

// The keys in `scope` that reader `readers` takes as doubles (rclcpp refuses an integer written for them).
std::vector<std::string> stvl_double_key_names(StvlScope scope, unsigned readers);

// Reads every source key `reader` takes that has a number or flag field from `map` into `source` (absent keys
// keep their value); keys named in `skip` are left to the caller.
void read_source_keys(YamlMap& map, mapping::ObservationSource& source, unsigned reader,
                      const std::vector<std::string>& skip = {});

}  // namespace stvl::config

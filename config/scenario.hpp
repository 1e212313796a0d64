#pragma once
// A scenario: which world, how the robot drives, the camera, the filter, the map, what is evaluated and which
// checks must pass. Loaded from YAML (scenarios/*.yaml); every key is documented in scenarios/README.md.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "config/ros_lint.hpp"
#include "evaluation/checks.hpp"
#include "evaluation/config.hpp"
#include "navigation/config.hpp"
#include "pipeline/pipeline.hpp"

namespace stvl::config {

// What a run writes besides its metrics.
struct OutputConfig {
  double publish_period_s = 1.0;     // map.publish_period_s: bag /stvl/voxel_grid and /stvl/costmap
  int sample_depth_frames = 3;       // evaluation.sample_depth_frames: depth frames saved as PNG for the report
  double soak_sample_every_s = 0.0;  // evaluation.soak_sample_every_s: resources sampled (tools/soak.hpp); 0 off
};

// map.ros_params: the STVL layer comes from a ROS parameter file.
struct RosParamsRef {
  std::string path;            // resolved against the scenario file's folder
  std::string layer, costmap;  // "" = the only one
};

struct Scenario {
  std::string name;
  std::string file;  // where it was loaded from
  double duration_s = 30.0;
  bool stop_at_path_end = true;
  // The world (resolved against the scenario file's folder), robot, camera, filter and map. The camera's
  // observation source takes its FOV from the camera unless the file gives one.
  pipeline::PipelineConfig pipeline;
  // The YAML's evaluation settings; evaluation_config() adds what follows from the map.
  evaluation::EvaluationConfig evaluation;
  evaluation::ChecksConfig checks;
  OutputConfig outputs;
  // navigation: the fixed path (mode path, the default) or nav2 driving to a goal from the costmaps (closed_loop;
  // then pipeline.path is empty and stop_at_path_end false).
  navigation::NavigationConfig navigation;
  // The nav2 parameter file the closed loop's servers came from ("" none), and its findings: plugins not modelled
  // and what stands in for them (config/ros_navigation.hpp).
  std::string navigation_ros_params;
  std::vector<LintFinding> navigation_findings;
  std::optional<RosParamsRef> ros_params;
  // "file:line: robot.cameras[i].mount" per camera ("" for the one-camera form), for errors the pipeline finds
  // only once the world is loaded (a camera inside the robot's body).
  std::vector<std::string> camera_mount_locations;
  // Where pipeline.map.footprint_B came from: "map.footprint", "map.robot_radius", "ros_params footprint (FILE)",
  // "ros_params robot_radius (FILE)", "URDF collision shapes (FILE)"; empty: no footprint.
  std::string footprint_source;

  pipeline::CameraConfig& camera() { return pipeline.cameras.front(); }
  const pipeline::CameraConfig& camera() const { return pipeline.cameras.front(); }
};

// The evaluation of a scenario: its evaluation settings at the map's voxel size and the camera source's
// marking band.
evaluation::EvaluationConfig evaluation_config(const Scenario& scenario);

// Throws std::invalid_argument naming the file, line and key for malformed files, unknown keys, wrong types
// and out-of-range values.
// `sets`: "dotted.key=VALUE" assignments applied to the document before it is read (stvl-bench run --set; see
// set_yaml_path); an error about a key one of them set starts "--set KEY=VALUE: ".
Scenario load_scenario(const std::string& path, const std::vector<std::string>& sets = {});
Scenario parse_scenario(const std::string& yaml_text, const std::string& file_name, const std::string& base_dir);

// Path of the default scenario (scenarios/office_corridor.yaml in the source tree).
std::string default_scenario_path();

// Command-line overrides applied after loading (empty/absent = keep the scenario's value).
struct ScenarioOverrides {
  std::optional<std::uint64_t> seed;
  std::optional<std::string> filter_type;
  std::optional<std::string> device;
  std::optional<std::string> memory;
  std::optional<double> voxel_size_m;  // sets the map's voxel_size and the filter's voxel size together
  std::optional<double> duration_s;
  std::optional<std::string> gl_backend;
  std::optional<bool> noise;
};
void apply_overrides(Scenario& scenario, const ScenarioOverrides& overrides);

}  // namespace stvl::config

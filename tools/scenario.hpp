#pragma once
// A scenario: which world, how the robot drives, the camera, the filter, the map, what is evaluated and which
// checks must pass. Loaded from YAML (scenarios/*.yaml); every key is documented in scenarios/README.md.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "filter/filter.hpp"
#include "mapping/config.hpp"
#include "sensors/camera.hpp"
#include "sensors/depth_noise.hpp"
#include "sensors/gl_context.hpp"
#include "sim/simulator.hpp"

namespace stvl::tools {

struct CameraConfig {
  std::string preset = "d435_848x480";  // d435_848x480 | d435_640x480 | custom
  sensors::CameraIntrinsics intrinsics = sensors::CameraIntrinsics::d435_848x480();
  sensors::GlBackend gl_backend = sensors::GlBackend::kAuto;
  sensors::DepthNoiseConfig noise;
};

// Thresholds of the pass/fail checks; a check whose threshold is absent is not run.
struct ChecksConfig {
  std::optional<double> f1_3d_min;
  std::optional<double> iou_3d_min;
  std::optional<double> costmap_precision_min;
  std::optional<double> costmap_recall_min;
  bool all_obstacles_detected = false;
  std::optional<int> phantom_obstacles_max;
  std::optional<double> clearing_latency_max_s;
  std::optional<double> accuracy_p90_max_m;
};

struct EvaluationConfig {
  // Recall counts true surface voxels seen by the (noise-free) camera within this window before each evaluation.
  double recall_window_s = 2.0;
  double evaluate_every_s = 1.0;
  int tolerance_voxels = 1;        // a mapped voxel within this many voxels (Chebyshev) of a truth voxel matches
  int min_observed_voxels = 3;     // an obstacle counts as observed once this many of its voxels were seen
  int phantom_min_cells = 2;       // lethal components smaller than this are not called phantoms
  // A lethal component is a phantom when no true footprint lies within this distance (metres, so that the
  // meaning does not change with the voxel size; 0.10 m is below a small robot's inflation radius).
  double phantom_clearance_m = 0.10;
  int sample_depth_frames = 3;     // depth frames saved as PNG for the report
};

struct Scenario {
  std::string name;
  std::string file;        // where it was loaded from
  std::string world_path;  // resolved against the scenario file's folder
  std::uint64_t seed = 1;
  double duration_s = 30.0;
  bool stop_at_path_end = true;
  sim::SimulatorConfig sim;
  sim::Pose2D start_pose;
  sim::Path path;
  std::vector<sim::MocapTrack> moving_bodies;
  CameraConfig camera;
  filter::FilterConfig filter;
  mapping::StvlConfig map;
  mapping::ObservationSource source;  // FOV filled from the camera unless given
  double voxel_grid_publish_period_s = 1.0;  // bag: /stvl/voxel_grid and /stvl/costmap
  EvaluationConfig evaluation;
  ChecksConfig checks;
};

// Throws std::invalid_argument naming the file, line and key for malformed files, unknown keys, wrong types
// and out-of-range values.
Scenario load_scenario(const std::string& path);
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

// The scenario's world with the robot at its start pose, on its path, and the moving bodies scripted.
std::unique_ptr<sim::Simulator> make_simulator(const Scenario& scenario);

}  // namespace stvl::tools

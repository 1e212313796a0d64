#pragma once
// Scenario texts and line edits shared by the scenario parser's tests.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "config/scenario.hpp"
#include "tests/support/invalid_argument.hpp"

namespace stvl::config::test {

using stvl::test::invalid_argument_of;

inline const char* const kMinimal = R"(name: minimal
world: w.xml
robot:
  waypoints: [[0, 0], [1, 0]]
  speed_mps: 0.5
)";

// Every key a scenario can hold, each set away from its default, in block style so that a line can be added
// after any of them.
inline const char* const kFull = R"(name: full
world: ../worlds/office_corridor.xml
seed: 7
duration_s: 12.5
stop_at_path_end: false
robot:
  start: [1.0, 2.0, 90.0]
  waypoints: [[1.0, 2.0], [5.0, 2.0], [5.0, 6.0]]
  speed_mps: 0.4
  camera_mount:
    height_m: 0.6
    pitch_deg: 10
    forward_offset_m: 0.2
  odometry_drift:
    enabled: true
    left_wheel_radius_error: 0.01
    right_wheel_radius_error: -0.02
    track_width_error: 0.03
    linear_noise_std_mps: 0.05
    angular_noise_std_radps: 0.06
moving_bodies:
  - body: person
    keyframes:
      - t: 1.0
        position: [3.0, 0.5, 0.0]
        yaw_deg: 90
      - t: 2.0
        position: [4.0, 0.5, 0.0]
        yaw_deg: 180
camera:
  preset: custom
  intrinsics:
    width: 320
    height: 240
    fx: 200.0
    fy: 210.0
    cx: 159.5
    cy: 119.5
  min_range_m: 0.2
  max_range_m: 8.0
  rate_hz: 10
  gl_backend: osmesa
  noise:
    enabled: false
    baseline_m: 0.06
    subpixel: 0.1
    disparity_step_px: 0.05
    edge_jump_m: 0.2
    edge_probability: 0.4
    edge_invalid_fraction: 0.3
    dropout_probability: 0.01
    holes_per_frame: 3
    hole_max_radius_px: 5
    stereo_occlusion: true
    left_band_margin_px: 10
    left_band_jitter_px: 1.5
    shadow_margin_px: 3
    correlated_fraction: 0.5
    correlated_cell_px: 8
filter:
  type: csnb
  device: cpu
  memory: pinned
  cpu_threads: 2
  passthrough:
    enabled: false
    min_z_m: 0.05
    max_z_m: 1.5
  voxel:
    voxel_size_m: 0.04
    min_points_per_voxel: 2
  csnb:
    voxel_size_m: 0.03
    max_neighbours: 6
    batch_size: 500
    grid_exponent: 5
map:
  voxel_size: 0.04
  voxel_decay: 10
  decay_model: exponential
  mark_threshold: 2
  clearing_mode: raycast
  clearing_walk: full_walk
  expiry_leaves_per_update: 64
  publish_period_s: 0.5
  observation:
    marking: true
    clearing: false
    obstacle_range: 3.5
    min_obstacle_height: 0.05
    max_obstacle_height: 1.8
    horizontal_fov_angle: 1.2
    vertical_fov_angle: 0.8
    min_z: 0.2
    max_z: 5.0
    decay_acceleration: 2.0
evaluation:
  recall_window_s: 3.0
  evaluate_every_s: 0.5
  tolerance_voxels: 2
  min_observed_voxels: 5
  phantom_min_cells: 3
  phantom_clearance_m: 0.2
  sample_depth_frames: 4
checks:
  f1_3d_min: 0.8
  iou_3d_min: 0.7
  costmap_precision_min: 0.9
  costmap_recall_min: 0.6
  all_obstacles_detected: true
  phantom_obstacles_max: 1
  clearing_latency_max_s: 1.5
  accuracy_p90_max_m: 0.05
)";

inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

inline std::string join(const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& line : lines) text += line + "\n";
  return text;
}

struct Edited {
  std::string yaml;
  int line;  // 1-based line of the inserted or replaced text
};

// Inserts `text` after the first line that starts with `anchor` (leading spaces included).
inline Edited insert_after(const std::string& yaml, const std::string& anchor, const std::string& text) {
  auto lines = lines_of(yaml);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].rfind(anchor, 0) == 0) {
      lines.insert(lines.begin() + static_cast<long>(i) + 1, text);
      return {join(lines), static_cast<int>(i) + 2};
    }
  }
  ADD_FAILURE() << "anchor '" << anchor << "' not found";
  return {yaml, 0};
}

// Replaces the first line that starts with `anchor` by `text`.
inline Edited replace_line(const std::string& yaml, const std::string& anchor, const std::string& text) {
  auto lines = lines_of(yaml);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].rfind(anchor, 0) == 0) {
      lines[i] = text;
      return {join(lines), static_cast<int>(i) + 1};
    }
  }
  ADD_FAILURE() << "anchor '" << anchor << "' not found";
  return {yaml, 0};
}

inline Scenario parse(const std::string& yaml) { return parse_scenario(yaml, "x.yaml", "/base/scenarios"); }

inline std::string error_of(const std::string& yaml) {
  return invalid_argument_of([&] { parse(yaml); });
}

inline std::string at(int line, const std::string& key) { return "x.yaml:" + std::to_string(line) + ": " + key + ": "; }

}  // namespace stvl::config::test

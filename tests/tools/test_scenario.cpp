#include "tools/scenario.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/tools/test_helpers.hpp"
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace stvl::tools {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using test::invalid_argument_of;
using ::testing::MatchesRegex;

const std::string kScenarioDir = std::string(STVL_SOURCE_DIR) + "/scenarios";


const char* const kMinimal = R"(name: minimal
world: w.xml
robot:
  waypoints: [[0, 0], [1, 0]]
  speed_mps: 0.5
)";

// Every key a scenario can hold, each set away from its default, in block style so that a line can be added
// after any of them.
const char* const kFull = R"(name: full
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

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::string join(const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& line : lines) text += line + "\n";
  return text;
}

struct Edited {
  std::string yaml;
  int line;  // 1-based line of the inserted or replaced text
};

// Inserts `text` after the first line that starts with `anchor` (leading spaces included).
Edited insert_after(const std::string& yaml, const std::string& anchor, const std::string& text) {
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
Edited replace_line(const std::string& yaml, const std::string& anchor, const std::string& text) {
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

Scenario parse(const std::string& yaml) { return parse_scenario(yaml, "x.yaml", "/base/scenarios"); }

std::string error_of(const std::string& yaml) { return invalid_argument_of([&] { parse(yaml); }); }

std::string at(int line, const std::string& key) { return "x.yaml:" + std::to_string(line) + ": " + key + ": "; }

TEST(ScenarioShipped, EveryScenarioInTheFolderLoads) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(kScenarioDir)) {
    if (entry.path().extension() != ".yaml") continue;
    ++count;
    SCOPED_TRACE(entry.path().string());
    Scenario s;
    ASSERT_NO_THROW(s = load_scenario(entry.path().string()));
    EXPECT_EQ(s.name, entry.path().stem().string());
    EXPECT_TRUE(fs::is_regular_file(s.pipeline.world_path)) << s.pipeline.world_path;
    EXPECT_GE(s.pipeline.path.waypoints_W.size(), 2u);
    const auto& c = s.checks;
    EXPECT_TRUE(c.f1_3d_min || c.iou_3d_min || c.costmap_precision_min || c.costmap_recall_min ||
                c.all_obstacles_detected || c.phantom_obstacles_max || c.clearing_latency_max_s || c.accuracy_p90_max_m)
        << "a shipped scenario checks nothing";
    EXPECT_DOUBLE_EQ(s.camera().source.horizontal_fov_rad, s.camera().intrinsics.hfov_rad());
  }
  EXPECT_GE(count, 7);
}

TEST(ScenarioShipped, DefaultScenarioIsTheOfficeCorridor) {
  EXPECT_TRUE(fs::is_regular_file(default_scenario_path()));
  EXPECT_EQ(load_scenario(default_scenario_path()).name, "office_corridor");
}

TEST(ScenarioParse, MinimalScenarioTakesTheDefaults) {
  const Scenario s = parse(kMinimal);
  const Scenario defaults;
  EXPECT_EQ(s.name, "minimal");
  EXPECT_EQ(s.file, "x.yaml");
  EXPECT_EQ(s.pipeline.seed, 1u);
  EXPECT_DOUBLE_EQ(s.duration_s, 30.0);
  EXPECT_TRUE(s.stop_at_path_end);
  EXPECT_EQ(s.pipeline.start_pose.x_m, 0.0);
  EXPECT_EQ(s.pipeline.start_pose.y_m, 0.0);
  EXPECT_EQ(s.pipeline.start_pose.yaw_rad, 0.0);
  ASSERT_EQ(s.pipeline.path.waypoints_W.size(), 2u);
  EXPECT_EQ(s.pipeline.path.waypoints_W[1], Eigen::Vector2d(1, 0));
  EXPECT_DOUBLE_EQ(s.pipeline.path.cruise_speed_mps, 0.5);
  EXPECT_DOUBLE_EQ(s.camera().intrinsics.fx, sensors::CameraIntrinsics::d435_848x480().fx);
  EXPECT_EQ(s.camera().intrinsics.width, 848);
  EXPECT_EQ(s.camera().gl_backend, sensors::GlBackend::kAuto);
  EXPECT_TRUE(s.camera().noise.enabled);
  EXPECT_EQ(s.pipeline.filter.type, filter::FilterType::kVoxel);
  EXPECT_EQ(s.pipeline.filter.device, filter::Device::kAuto);
  EXPECT_DOUBLE_EQ(s.pipeline.map.voxel_size_m, defaults.pipeline.map.voxel_size_m);
  EXPECT_DOUBLE_EQ(s.pipeline.map.voxel_decay_s, 15.0);
  EXPECT_TRUE(s.camera().source.marking);
  EXPECT_TRUE(s.camera().source.clearing);
  EXPECT_DOUBLE_EQ(s.evaluation.recall_window_s, 2.0);
  EXPECT_FALSE(s.checks.f1_3d_min);
  EXPECT_FALSE(s.checks.all_obstacles_detected);
  EXPECT_TRUE(s.pipeline.moving_bodies.empty());
  EXPECT_DOUBLE_EQ(s.outputs.publish_period_s, 1.0);
}

TEST(ScenarioParse, EveryKeyIsRead) {
  const Scenario s = parse(kFull);
  EXPECT_EQ(s.pipeline.world_path, "/base/worlds/office_corridor.xml");
  EXPECT_EQ(s.pipeline.seed, 7u);
  EXPECT_DOUBLE_EQ(s.duration_s, 12.5);
  EXPECT_FALSE(s.stop_at_path_end);
  EXPECT_DOUBLE_EQ(s.pipeline.start_pose.x_m, 1.0);
  EXPECT_DOUBLE_EQ(s.pipeline.start_pose.y_m, 2.0);
  EXPECT_NEAR(s.pipeline.start_pose.yaw_rad, M_PI / 2, 1e-12);
  ASSERT_EQ(s.pipeline.path.waypoints_W.size(), 3u);
  EXPECT_EQ(s.pipeline.path.waypoints_W[2], Eigen::Vector2d(5, 6));
  EXPECT_DOUBLE_EQ(s.pipeline.path.cruise_speed_mps, 0.4);
  EXPECT_DOUBLE_EQ(s.pipeline.sim.camera_mount.height_m, 0.6);
  EXPECT_NEAR(s.pipeline.sim.camera_mount.pitch_rad, 10 * M_PI / 180, 1e-12);
  EXPECT_DOUBLE_EQ(s.pipeline.sim.camera_mount.forward_offset_m, 0.2);
  EXPECT_TRUE(s.pipeline.sim.odometry.drift);
  EXPECT_DOUBLE_EQ(s.pipeline.sim.odometry.left_wheel_radius_error, 0.01);
  EXPECT_DOUBLE_EQ(s.pipeline.sim.odometry.right_wheel_radius_error, -0.02);
  EXPECT_DOUBLE_EQ(s.pipeline.sim.odometry.track_width_error, 0.03);
  EXPECT_DOUBLE_EQ(s.pipeline.sim.odometry.linear_noise_std_mps, 0.05);
  EXPECT_DOUBLE_EQ(s.pipeline.sim.odometry.angular_noise_std_radps, 0.06);
  EXPECT_EQ(s.pipeline.sim.odometry.seed, 7u);
  ASSERT_EQ(s.pipeline.moving_bodies.size(), 1u);
  EXPECT_EQ(s.pipeline.moving_bodies[0].body, "person");
  ASSERT_EQ(s.pipeline.moving_bodies[0].keyframes.size(), 2u);
  EXPECT_DOUBLE_EQ(s.pipeline.moving_bodies[0].keyframes[1].time_s, 2.0);
  EXPECT_EQ(s.pipeline.moving_bodies[0].keyframes[1].position_W, Eigen::Vector3d(4.0, 0.5, 0.0));
  ASSERT_TRUE(s.pipeline.moving_bodies[0].keyframes[1].yaw_rad);
  EXPECT_NEAR(*s.pipeline.moving_bodies[0].keyframes[1].yaw_rad, M_PI, 1e-12);
  const auto& k = s.camera().intrinsics;
  EXPECT_EQ(k.width, 320);
  EXPECT_EQ(k.height, 240);
  EXPECT_DOUBLE_EQ(k.fx, 200.0);
  EXPECT_DOUBLE_EQ(k.fy, 210.0);  // fx != fy parses; the renderer decides whether it can draw it
  EXPECT_DOUBLE_EQ(k.cx, 159.5);
  EXPECT_DOUBLE_EQ(k.cy, 119.5);
  EXPECT_DOUBLE_EQ(k.min_range_m, 0.2);
  EXPECT_DOUBLE_EQ(k.max_range_m, 8.0);
  EXPECT_DOUBLE_EQ(k.rate_hz, 10.0);
  EXPECT_EQ(s.camera().gl_backend, sensors::GlBackend::kOsmesa);
  const auto& n = s.camera().noise;
  EXPECT_FALSE(n.enabled);
  EXPECT_DOUBLE_EQ(n.baseline_m, 0.06);
  EXPECT_DOUBLE_EQ(n.subpixel, 0.1);
  EXPECT_DOUBLE_EQ(n.disparity_step_px, 0.05);
  EXPECT_DOUBLE_EQ(n.edge_jump_m, 0.2);
  EXPECT_DOUBLE_EQ(n.edge_probability, 0.4);
  EXPECT_DOUBLE_EQ(n.edge_invalid_fraction, 0.3);
  EXPECT_DOUBLE_EQ(n.dropout_probability, 0.01);
  EXPECT_DOUBLE_EQ(n.holes_per_frame, 3.0);
  EXPECT_DOUBLE_EQ(n.hole_max_radius_px, 5.0);
  const auto& f = s.pipeline.filter;
  EXPECT_EQ(f.type, filter::FilterType::kCsnb);
  EXPECT_EQ(f.device, filter::Device::kCpu);
  EXPECT_EQ(f.memory, filter::MemoryMode::kPinned);
  EXPECT_EQ(f.cpu_threads, 2);
  EXPECT_FALSE(f.passthrough_enabled);
  EXPECT_DOUBLE_EQ(f.passthrough.min_z_m, 0.05);
  EXPECT_DOUBLE_EQ(f.passthrough.max_z_m, 1.5);
  EXPECT_DOUBLE_EQ(f.voxel.voxel_size_m, 0.04);
  EXPECT_EQ(f.voxel.min_points_per_voxel, 2);
  EXPECT_DOUBLE_EQ(f.csnb.voxel_size_m, 0.03);
  EXPECT_EQ(f.csnb.max_neighbours, 6);
  EXPECT_EQ(f.csnb.batch_size, 500);
  EXPECT_EQ(f.csnb.grid_exponent, 5);
  EXPECT_EQ(f.csnb.seed, 7u);
  const auto& m = s.pipeline.map;
  EXPECT_DOUBLE_EQ(m.voxel_size_m, 0.04);
  EXPECT_DOUBLE_EQ(m.voxel_decay_s, 10.0);
  EXPECT_EQ(m.decay_model, mapping::DecayModel::kExponential);
  EXPECT_EQ(m.mark_threshold, 2);
  EXPECT_EQ(m.clearing_mode, mapping::ClearingMode::kRaycast);
  EXPECT_EQ(m.clearing_walk, mapping::ClearingWalk::kFullWalk);
  EXPECT_EQ(m.expiry_leaves_per_update, 64u);
  EXPECT_DOUBLE_EQ(s.outputs.publish_period_s, 0.5);
  const auto& o = s.camera().source;
  EXPECT_TRUE(o.marking);
  EXPECT_FALSE(o.clearing);
  EXPECT_DOUBLE_EQ(o.obstacle_range_m, 3.5);
  EXPECT_DOUBLE_EQ(o.min_obstacle_height_m, 0.05);
  EXPECT_DOUBLE_EQ(o.max_obstacle_height_m, 1.8);
  EXPECT_DOUBLE_EQ(o.horizontal_fov_rad, 1.2);
  EXPECT_DOUBLE_EQ(o.vertical_fov_rad, 0.8);
  EXPECT_DOUBLE_EQ(o.min_z_m, 0.2);
  EXPECT_DOUBLE_EQ(o.max_z_m, 5.0);
  EXPECT_DOUBLE_EQ(o.decay_acceleration_per_s3, 2.0);
  const auto& e = s.evaluation;
  EXPECT_DOUBLE_EQ(e.recall_window_s, 3.0);
  EXPECT_DOUBLE_EQ(e.evaluate_every_s, 0.5);
  EXPECT_EQ(e.tolerance_voxels, 2);
  EXPECT_EQ(e.min_observed_voxels, 5);
  EXPECT_EQ(e.phantom_min_cells, 3);
  EXPECT_DOUBLE_EQ(e.phantom_clearance_m, 0.2);
  EXPECT_EQ(s.outputs.sample_depth_frames, 4);
  const auto& c = s.checks;
  EXPECT_EQ(c.f1_3d_min, 0.8);
  EXPECT_EQ(c.iou_3d_min, 0.7);
  EXPECT_EQ(c.costmap_precision_min, 0.9);
  EXPECT_EQ(c.costmap_recall_min, 0.6);
  EXPECT_TRUE(c.all_obstacles_detected);
  EXPECT_EQ(c.phantom_obstacles_max, 1);
  EXPECT_EQ(c.clearing_latency_max_s, 1.5);
  EXPECT_EQ(c.accuracy_p90_max_m, 0.05);
}

TEST(ScenarioParse, UnknownKeysAtEveryLevelNameFileLineAndDottedKey) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"seed:", "bogus"},
      {"  speed_mps:", "robot.bogus"},
      {"    forward_offset_m:", "robot.camera_mount.bogus"},
      {"    angular_noise_std_radps:", "robot.odometry_drift.bogus"},
      {"  - body:", "moving_bodies[0].bogus"},
      {"        yaw_deg: 90", "moving_bodies[0].keyframes[0].bogus"},
      {"  preset:", "camera.bogus"},
      {"    cy:", "camera.intrinsics.bogus"},
      {"    hole_max_radius_px:", "camera.noise.bogus"},
      {"  cpu_threads:", "filter.bogus"},
      {"    max_z_m:", "filter.passthrough.bogus"},
      {"    min_points_per_voxel:", "filter.voxel.bogus"},
      {"    grid_exponent:", "filter.csnb.bogus"},
      {"  publish_period_s:", "map.bogus"},
      {"    decay_acceleration:", "map.observation.bogus"},
      {"  sample_depth_frames:", "evaluation.bogus"},
      {"  accuracy_p90_max_m:", "checks.bogus"},
  };
  for (const auto& [anchor, dotted] : cases) {
    SCOPED_TRACE(dotted);
    const std::string indent(anchor.find_first_not_of(" -"), ' ');
    const Edited e = insert_after(kFull, anchor, indent + "bogus: 1");
    EXPECT_THAT(error_of(e.yaml), HasSubstr(at(e.line, dotted) + "unknown key"));
  }
}

TEST(ScenarioParse, ATypoIsReportedAsInTheExample) {
  const Edited e = replace_line(kFull, "    min_z:", "    voxel_sze: 0.1");
  const std::string message = error_of(e.yaml);
  EXPECT_THAT(message, HasSubstr(at(e.line, "map.observation.voxel_sze") + "unknown key"));
  EXPECT_THAT(message, HasSubstr("max_z"));  // the known keys are listed
}

TEST(ScenarioParse, UnknownKeyInAFlowMapping) {
  const Edited e = insert_after(kMinimal, "  speed_mps:", "  camera_mount: {height_m: 0.5, pitch_dg: 5}");
  EXPECT_THAT(error_of(e.yaml), HasSubstr(at(e.line, "robot.camera_mount.pitch_dg") + "unknown key"));
}

TEST(ScenarioParse, IntrinsicsWithAPresetAreRejected) {
  const Edited e = insert_after(kMinimal, "  speed_mps:", "camera:\n  preset: d435_640x480\n  intrinsics: {fx: 1}");
  EXPECT_THAT(error_of(e.yaml), HasSubstr(at(e.line + 2, "camera.intrinsics") + "only used with preset: custom"));
}

TEST(ScenarioParse, WrongTypesNameKeyAndLine) {
  struct Case {
    std::string anchor, replacement, expected;
  };
  const std::vector<Case> cases = {
      {"duration_s:", "duration_s: fast", "duration_s: expected a number, got 'fast'"},
      {"seed:", "seed: -1", "seed: expected a non-negative integer, got '-1'"},
      {"seed:", "seed: 1.5", "seed: expected a non-negative integer"},
      {"name:", "name: [a, b]", "name: expected a string"},
      {"  waypoints:", "  waypoints: 5", "robot.waypoints: expected a list of number lists, got '5'"},
      {"  waypoints:", "  waypoints: [1, 2]", "robot.waypoints: expected a list of number lists"},
      {"  waypoints:", "  waypoints: [[0, 0, 0], [1, 1, 1]]", "robot.waypoints: expected [x, y] points"},
      {"  start:", "  start: 0", "robot.start: expected a list of numbers, got '0'"},
      {"  start:", "  start: [1, 2]", "robot.start: expected [x_m, y_m, yaw_deg]"},
      {"  speed_mps:", "  speed_mps: fast", "robot.speed_mps: expected a number"},
      {"    width:", "    width: 320.5", "camera.intrinsics.width: expected an integer, got '320.5'"},
      {"  tolerance_voxels:", "  tolerance_voxels: 1.5", "evaluation.tolerance_voxels: expected an integer, got '1.5'"},
      {"  phantom_obstacles_max:", "  phantom_obstacles_max: 0.5", "checks.phantom_obstacles_max: expected an integer"},
      {"    enabled: false", "    enabled: maybe", "camera.noise.enabled: expected a boolean, got 'maybe'"},
      {"        position:", "        position: [1, 2]", "moving_bodies[0].keyframes[0].position: expected [x, y, z]"},
      {"  voxel_size:", "  voxel_size: [0.05]", "map.voxel_size: expected a number, got 'a list'"},
      {"  voxel_size:", "  voxel_size:", "map.voxel_size: expected a number, got nothing"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.replacement);
    const Edited e = replace_line(kFull, c.anchor, c.replacement);
    const std::string message = error_of(e.yaml);
    EXPECT_THAT(message, HasSubstr("x.yaml:" + std::to_string(e.line) + ": " + c.expected));
  }
}

TEST(ScenarioParse, SectionsOfTheWrongKind) {
  EXPECT_THAT(error_of(std::string(kMinimal) + "camera: d435\n"), HasSubstr("x.yaml:6: camera: expected a mapping, got 'd435'"));
  EXPECT_THAT(error_of(std::string(kMinimal) + "moving_bodies: {body: x}\n"), HasSubstr("x.yaml:6: moving_bodies: expected a list"));
  EXPECT_THAT(error_of(std::string(kMinimal) + "moving_bodies: [5]\n"), HasSubstr("x.yaml:6: moving_bodies[0]: expected a mapping"));
  EXPECT_THAT(error_of("name: a\nworld: b\nrobot: [1]\n"), HasSubstr("x.yaml:3: robot: expected a mapping"));
  EXPECT_THAT(error_of(std::string(kMinimal) + "map:\n  observation: 3\n"), HasSubstr("x.yaml:7: map.observation: expected a mapping"));
}

TEST(ScenarioParse, MissingRequiredKeys) {
  EXPECT_THAT(error_of(replace_line(kMinimal, "name:", "").yaml), HasSubstr("x.yaml:2: name: required key is missing"));
  EXPECT_THAT(error_of(replace_line(kMinimal, "world:", "").yaml), HasSubstr("world: required key is missing"));
  EXPECT_THAT(error_of("name: a\nworld: b\n"), HasSubstr("robot: required mapping is missing"));
  EXPECT_THAT(error_of(replace_line(kMinimal, "  waypoints:", "").yaml), HasSubstr("x.yaml:3: robot.waypoints: required key is missing"));
  EXPECT_THAT(error_of(replace_line(kMinimal, "  speed_mps:", "").yaml), HasSubstr("robot.speed_mps: required key is missing"));
  EXPECT_THAT(error_of(replace_line(kFull, "  intrinsics:", "  no_intrinsics:").yaml), HasSubstr("camera.intrinsics: required mapping is missing"));
  EXPECT_THAT(error_of(replace_line(kFull, "    fy:", "").yaml), HasSubstr("camera.intrinsics.fy: required key is missing"));
  EXPECT_THAT(error_of(replace_line(kFull, "      - t: 1.0", "      - tt: 1.0").yaml), HasSubstr("moving_bodies[0].keyframes[0].t: required key is missing"));
  EXPECT_THAT(error_of(replace_line(kFull, "  - body:", "  - name: person").yaml), HasSubstr("moving_bodies[0].body: required key is missing"));
  EXPECT_THAT(error_of(std::string(kMinimal) + "moving_bodies:\n  - body: person\n"), HasSubstr("moving_bodies[0].keyframes: at least one keyframe"));
}

TEST(ScenarioParse, SyntaxErrorsNameTheLine) {
  EXPECT_THAT(error_of("name: a\nworld: b\nrobot:\n  waypoints: [[0, 0], [1, 0]\n  speed_mps: 0.5\n"),
              MatchesRegex("x\\.yaml:[4-6]: YAML syntax error: .*"));
  EXPECT_THAT(error_of("name: a\nworld: b\n  robot: 1\n"), MatchesRegex("x\\.yaml:3: YAML syntax error: .*"));
  EXPECT_THAT(error_of(""), HasSubstr("x.yaml:1: document: expected a mapping"));
}

TEST(ScenarioParse, DuplicateKeysAreRejected) {
  const Edited e = insert_after(kFull, "  voxel_size:", "  voxel_size: 0.1");
  EXPECT_THAT(error_of(e.yaml), HasSubstr(at(e.line, "map.voxel_size") + "duplicate key"));
}

TEST(ScenarioParse, OutOfRangeValuesNameKeyAndLine) {
  struct Case {
    std::string anchor, replacement, expected;
  };
  const std::vector<Case> cases = {
      {"  voxel_size:", "  voxel_size: -0.05", "map.voxel_size: voxel_size = -0.05 is invalid"},
      {"  voxel_size:", "  voxel_size: .nan", "map.voxel_size: voxel_size = nan is invalid"},
      {"  voxel_decay:", "  voxel_decay: -1", "map.voxel_decay: voxel_decay = -1 is invalid"},
      {"  decay_model:", "  decay_model: cubic", "map.decay_model:"},
      {"  clearing_mode:", "  clearing_mode: magic", "map.clearing_mode:"},
      {"  clearing_walk:", "  clearing_walk: sometimes", "map.clearing_walk:"},
      {"  mark_threshold:", "  mark_threshold: -1", "map.mark_threshold:"},
      {"  expiry_leaves_per_update:", "  expiry_leaves_per_update: 0", "map.expiry_leaves_per_update: must be >= 1"},
      {"  publish_period_s:", "  publish_period_s: 0", "map.publish_period_s: must be finite and > 0 s"},
      {"    horizontal_fov_angle:", "    horizontal_fov_angle: 3.5", "map.observation.horizontal_fov_angle:"},
      {"    horizontal_fov_angle:", "    horizontal_fov_angle: .nan", "map.observation.horizontal_fov_angle:"},
      {"    vertical_fov_angle:", "    vertical_fov_angle: 0", "map.observation.vertical_fov_angle:"},
      {"    obstacle_range:", "    obstacle_range: -1", "map.observation.obstacle_range:"},
      {"    min_z:", "    min_z: 6", "map.observation.min_z:"},
      {"    min_obstacle_height:", "    min_obstacle_height: 2", "map.observation.min_obstacle_height:"},
      {"    decay_acceleration:", "    decay_acceleration: -2", "map.observation.decay_acceleration:"},
      {"duration_s:", "duration_s: 0", "duration_s: must lie in (0, 3600] s"},
      {"duration_s:", "duration_s: -3", "duration_s: must lie in (0, 3600] s"},
      {"duration_s:", "duration_s: .nan", "duration_s: must lie in (0, 3600] s"},
      {"duration_s:", "duration_s: .inf", "duration_s: must lie in (0, 3600] s"},
      {"  preset:", "  preset: d999", "camera.preset: unknown preset 'd999'"},
      {"  gl_backend:", "  gl_backend: glx", "camera.gl_backend: GL backend 'glx'"},
      {"  rate_hz:", "  rate_hz: 0", "camera.rate_hz:"},
      {"  max_range_m:", "  max_range_m: 0.1", "camera.max_range_m:"},
      {"    width:", "    width: 0", "camera.intrinsics.width:"},
      {"    fx:", "    fx: -200", "camera.intrinsics.fx:"},
      {"    dropout_probability:", "    dropout_probability: 1.5", "camera.noise.dropout_probability:"},
      {"    baseline_m:", "    baseline_m: 0", "camera.noise.baseline_m:"},
      {"  type:", "  type: median", "filter.type: filter: unknown"},
      {"  device:", "  device: tpu", "filter.device: filter: unknown"},
      {"  memory:", "  memory: shared", "filter.memory: filter: unknown"},
      {"  cpu_threads:", "  cpu_threads: -1", "filter.cpu_threads: must be >= 0"},
      {"    min_z_m:", "    min_z_m: 2.0", "filter.passthrough.min_z_m: must be a number <= max_z_m"},
      {"    min_z_m:", "    min_z_m: .nan", "filter.passthrough.min_z_m:"},
      {"    voxel_size_m: 0.04", "    voxel_size_m: -0.04", "filter.voxel.voxel_size_m: must be finite and > 0 m"},
      {"    voxel_size_m: 0.03", "    voxel_size_m: .inf", "filter.csnb.voxel_size_m: must be finite and > 0 m"},
      {"    batch_size:", "    batch_size: 0", "filter.csnb.batch_size: must be >= 1"},
      {"    grid_exponent:", "    grid_exponent: 12", "filter.csnb.grid_exponent: must be 0 (auto) or 4..9"},
      {"  speed_mps:", "  speed_mps: 5", "robot.speed_mps:"},
      {"  speed_mps:", "  speed_mps: -0.5", "robot.speed_mps:"},
      {"  waypoints:", "  waypoints: [[1.0, 2.0]]", "robot.waypoints: path needs at least 2 waypoints"},
      {"  waypoints:", "  waypoints: [[1.0, 2.0], [1.0, 2.0]]", "robot.waypoints:"},
      {"  start:", "  start: [.nan, 0, 0]", "robot.start: must be finite"},
      {"    linear_noise_std_mps:", "    linear_noise_std_mps: -1", "robot.odometry_drift.linear_noise_std_mps:"},
      {"  recall_window_s:", "  recall_window_s: 0", "evaluation.recall_window_s: must be finite and > 0 s"},
      {"  evaluate_every_s:", "  evaluate_every_s: -1", "evaluation.evaluate_every_s: must be finite and > 0 s"},
      {"  tolerance_voxels:", "  tolerance_voxels: 4", "evaluation.tolerance_voxels: must lie in 0..3"},
      {"  min_observed_voxels:", "  min_observed_voxels: 0", "evaluation.min_observed_voxels: must be >= 1"},
      {"  sample_depth_frames:", "  sample_depth_frames: -1", "evaluation.sample_depth_frames:"},
      {"  f1_3d_min:", "  f1_3d_min: 1.5", "checks.f1_3d_min: must lie in [0, 1]"},
      {"  costmap_recall_min:", "  costmap_recall_min: .nan", "checks.costmap_recall_min: must lie in [0, 1]"},
      {"  phantom_obstacles_max:", "  phantom_obstacles_max: -1", "checks.phantom_obstacles_max: must be >= 0"},
      {"  clearing_latency_max_s:", "  clearing_latency_max_s: -1", "checks.clearing_latency_max_s:"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.replacement);
    const Edited e = replace_line(kFull, c.anchor, c.replacement);
    EXPECT_THAT(error_of(e.yaml), HasSubstr("x.yaml:" + std::to_string(e.line) + ": " + c.expected));
  }
}

TEST(ScenarioParse, PresetsSetTheIntrinsics) {
  const Scenario s = parse(std::string(kMinimal) + "camera: {preset: d435_640x480, rate_hz: 6}\n");
  EXPECT_EQ(s.camera().intrinsics.width, 640);
  EXPECT_EQ(s.camera().intrinsics.height, 480);
  EXPECT_DOUBLE_EQ(s.camera().intrinsics.rate_hz, 6.0);
}

TEST(ScenarioParse, ClearingFrustumFovDefaultsToTheCamera) {
  const Scenario wide = parse(kMinimal);
  EXPECT_DOUBLE_EQ(wide.camera().source.horizontal_fov_rad, sensors::CameraIntrinsics::d435_848x480().hfov_rad());
  EXPECT_DOUBLE_EQ(wide.camera().source.vertical_fov_rad, sensors::CameraIntrinsics::d435_848x480().vfov_rad());

  const Scenario narrow = parse(std::string(kMinimal) + "camera: {preset: d435_640x480}\nmap:\n  observation: {max_z: 4}\n");
  EXPECT_DOUBLE_EQ(narrow.camera().source.horizontal_fov_rad, sensors::CameraIntrinsics::d435_640x480().hfov_rad());
  EXPECT_DOUBLE_EQ(narrow.camera().source.vertical_fov_rad, sensors::CameraIntrinsics::d435_640x480().vfov_rad());
  EXPECT_LT(narrow.camera().source.horizontal_fov_rad, wide.camera().source.horizontal_fov_rad);
  EXPECT_DOUBLE_EQ(narrow.camera().source.max_z_m, 4.0);

  const Scenario custom = parse(replace_line(kFull, "    vertical_fov_angle:", "").yaml);
  EXPECT_DOUBLE_EQ(custom.camera().source.horizontal_fov_rad, 1.2);
  EXPECT_DOUBLE_EQ(custom.camera().source.vertical_fov_rad, custom.camera().intrinsics.vfov_rad());
}

TEST(ScenarioParse, RelativeWorldPathsResolveAgainstTheScenarioFolder) {
  EXPECT_EQ(parse_scenario(kMinimal, "x.yaml", "/a/b/scenarios").pipeline.world_path, "/a/b/scenarios/w.xml");
  const std::string up = replace_line(kMinimal, "world:", "world: ../worlds/./w.xml").yaml;
  EXPECT_EQ(parse_scenario(up, "x.yaml", "/a/b/scenarios").pipeline.world_path, "/a/b/worlds/w.xml");
  const std::string absolute = replace_line(kMinimal, "world:", "world: /abs/w.xml").yaml;
  EXPECT_EQ(parse_scenario(absolute, "x.yaml", "/a/b/scenarios").pipeline.world_path, "/abs/w.xml");
  EXPECT_THAT(error_of(replace_line(kMinimal, "world:", "world: ''").yaml), HasSubstr("world: must not be empty"));
}

TEST(ScenarioParse, LoadScenarioResolvesAgainstTheFilesFolder) {
  const fs::path dir = fs::temp_directory_path() / ("stvl_scenario_" + std::to_string(::getpid()));
  fs::create_directories(dir / "sub");
  const fs::path file = dir / "sub" / "s.yaml";
  std::ofstream(file) << replace_line(kMinimal, "world:", "world: ../worlds/w.xml").yaml;
  const Scenario s = load_scenario(file.string());
  EXPECT_EQ(s.file, file.string());
  EXPECT_EQ(s.pipeline.world_path, (dir / "worlds" / "w.xml").string());
  std::ofstream(file) << "name: a\nworld: b\nrobot:\n  waypoints: [[0, 0], [1, 0]]\n  speed_mps: 0.5\n  bogus: 1\n";
  EXPECT_THAT(invalid_argument_of([&] { load_scenario(file.string()); }), HasSubstr(file.string() + ":6: robot.bogus: unknown key"));
  fs::remove_all(dir);
  EXPECT_THAT(invalid_argument_of([&] { load_scenario(file.string()); }), HasSubstr(file.string() + ": no such file"));
}

TEST(ScenarioOverrides, EmptyOverridesChangeNothing) {
  Scenario s = parse(kFull);
  apply_overrides(s, {});
  EXPECT_EQ(s.pipeline.seed, 7u);
  EXPECT_EQ(s.pipeline.filter.type, filter::FilterType::kCsnb);
  EXPECT_DOUBLE_EQ(s.pipeline.map.voxel_size_m, 0.04);
  EXPECT_DOUBLE_EQ(s.duration_s, 12.5);
  EXPECT_FALSE(s.camera().noise.enabled);
}

TEST(ScenarioOverrides, EachOverrideChangesWhatItNames) {
  Scenario s = parse(kFull);
  ScenarioOverrides o;
  o.seed = 42;
  o.filter_type = "voxel";
  o.device = "auto";
  o.memory = "managed";
  o.voxel_size_m = 0.1;
  o.duration_s = 3.0;
  o.gl_backend = "egl";
  o.noise = true;
  apply_overrides(s, o);
  EXPECT_EQ(s.pipeline.seed, 42u);
  EXPECT_EQ(s.pipeline.filter.csnb.seed, 42u);
  EXPECT_EQ(s.pipeline.sim.odometry.seed, 42u);
  EXPECT_EQ(s.pipeline.filter.type, filter::FilterType::kVoxel);
  EXPECT_EQ(s.pipeline.filter.device, filter::Device::kAuto);
  EXPECT_EQ(s.pipeline.filter.memory, filter::MemoryMode::kManaged);
  EXPECT_DOUBLE_EQ(s.pipeline.map.voxel_size_m, 0.1);
  EXPECT_DOUBLE_EQ(s.pipeline.filter.voxel.voxel_size_m, 0.1);
  EXPECT_DOUBLE_EQ(s.pipeline.filter.csnb.voxel_size_m, 0.1);
  EXPECT_DOUBLE_EQ(s.duration_s, 3.0);
  EXPECT_EQ(s.camera().gl_backend, sensors::GlBackend::kEgl);
  EXPECT_TRUE(s.camera().noise.enabled);
  // Untouched values stay.
  EXPECT_DOUBLE_EQ(s.pipeline.map.voxel_decay_s, 10.0);
  EXPECT_EQ(s.camera().intrinsics.width, 320);
}

TEST(ScenarioOverrides, BadValuesAreRejectedNamingTheOptionAndChangeNothing) {
  struct Case {
    ScenarioOverrides overrides;
    std::string expected;
  };
  std::vector<Case> cases(9);
  cases[0].overrides.voxel_size_m = 0.0, cases[0].expected = "--voxel-size: voxel_size = 0 is invalid";
  cases[1].overrides.voxel_size_m = std::nan(""), cases[1].expected = "--voxel-size: voxel_size = nan is invalid";
  cases[2].overrides.voxel_size_m = -0.05, cases[2].expected = "--voxel-size:";
  cases[3].overrides.duration_s = 0.0, cases[3].expected = "--duration: must lie in (0, 3600] s";
  cases[4].overrides.duration_s = std::nan(""), cases[4].expected = "--duration:";
  cases[5].overrides.filter_type = "median", cases[5].expected = "--filter: filter: unknown";
  cases[6].overrides.device = "tpu", cases[6].expected = "--device:";
  cases[7].overrides.memory = "shared", cases[7].expected = "--memory:";
  cases[8].overrides.gl_backend = "glx", cases[8].expected = "--gl: GL backend 'glx'";
  for (auto& c : cases) {
    SCOPED_TRACE(c.expected);
    c.overrides.seed = 99;  // applied before the bad value: must not stick either
    Scenario s = parse(kFull);
    EXPECT_THAT(invalid_argument_of([&] { apply_overrides(s, c.overrides); }), HasSubstr(c.expected));
    EXPECT_EQ(s.pipeline.seed, 7u);
    EXPECT_DOUBLE_EQ(s.pipeline.map.voxel_size_m, 0.04);
    EXPECT_DOUBLE_EQ(s.pipeline.filter.voxel.voxel_size_m, 0.04);
    EXPECT_DOUBLE_EQ(s.duration_s, 12.5);
  }
}

}  // namespace
}  // namespace stvl::tools

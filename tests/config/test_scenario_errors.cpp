// The scenario parser's errors: every one names the file, the line and the dotted key.
#include "config/scenario.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/config/scenario_texts.hpp"

namespace stvl::config {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::MatchesRegex;
using ::testing::Not;
using namespace test;

const std::string kScenarioDir = std::string(STVL_SOURCE_DIR) + "/scenarios";

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
  EXPECT_THAT(error_of(e.yaml),
              HasSubstr(at(e.line, "robot.camera_mount.pitch_dg") + "unknown key; did you mean 'pitch_deg'?"));
}

TEST(ScenarioParse, TyposOfKeysAndNamesSuggestTheNearestKnownOne) {
  const Edited key = replace_line(kFull, "  voxel_size:", "  voxel_sze: 0.04");
  EXPECT_THAT(error_of(key.yaml), HasSubstr(at(key.line, "map.voxel_sze") + "unknown key; did you mean 'voxel_size'?"));
  const Edited value = replace_line(kFull, "  clearing_mode:", "  clearing_mode: raycats");
  EXPECT_THAT(error_of(value.yaml),
              HasSubstr(at(value.line, "map.clearing_mode") +
                        "unknown clearing_mode 'raycats' (expected frustum|raycast; did you mean 'raycast'?)"));
  const Edited far = replace_line(kFull, "  voxel_size:", "  colour: 3");
  EXPECT_THAT(error_of(far.yaml), Not(HasSubstr("did you mean")));
}

// map.nav2_costmap and an observation's clearing model: bad values name the key, the file and the line.
TEST(ScenarioParse, Nav2CostmapAndClearingModelErrors) {
  const Edited window = replace_line(kFull, "  voxel_size:", "  nav2_costmap: {width_m: 5, height_m: 0}");
  EXPECT_THAT(error_of(window.yaml), HasSubstr(at(window.line, "map.nav2_costmap.height_m") + "must be > 0 m"));
  const Edited typo =
      replace_line(kFull, "  voxel_size:", "  nav2_costmap: {width_m: 5, height_m: 5, rolling_windw: false}");
  EXPECT_THAT(error_of(typo.yaml), HasSubstr("did you mean 'rolling_window'?"));
  const Edited method =
      replace_line(kFull, "  voxel_size:", "  nav2_costmap: {width_m: 5, height_m: 5, combination_method: 2}");
  EXPECT_THAT(error_of(method.yaml), HasSubstr("map.nav2_costmap.combination_method"));
  const Edited model = replace_line(kFull, "    min_z:", "    model_type: 2");
  EXPECT_THAT(error_of(model.yaml), HasSubstr(at(model.line, "map.observation.model_type") + "STVL knows 0"));
  const Edited frame = replace_line(kFull, "    min_z:", "    sensor_frame: base_link");
  EXPECT_THAT(error_of(frame.yaml), HasSubstr(at(frame.line, "map.observation.sensor_frame")));
  const Edited band = replace_line(kFull, "    min_z:", "    z_reference_frame: base_footprint");
  EXPECT_THAT(error_of(band.yaml), HasSubstr(at(band.line, "map.observation.z_reference_frame")));
  EXPECT_THAT(error_of(band.yaml), HasSubstr("base_link"));  // names what it knows
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
  EXPECT_THAT(error_of(std::string(kMinimal) + "camera: d435\n"),
              HasSubstr("x.yaml:6: camera: expected a mapping, got 'd435'"));
  EXPECT_THAT(error_of(std::string(kMinimal) + "moving_bodies: {body: x}\n"),
              HasSubstr("x.yaml:6: moving_bodies: expected a list"));
  EXPECT_THAT(error_of(std::string(kMinimal) + "moving_bodies: [5]\n"),
              HasSubstr("x.yaml:6: moving_bodies[0]: expected a mapping"));
  EXPECT_THAT(error_of("name: a\nworld: b\nrobot: [1]\n"), HasSubstr("x.yaml:3: robot: expected a mapping"));
  EXPECT_THAT(error_of(std::string(kMinimal) + "map:\n  observation: 3\n"),
              HasSubstr("x.yaml:7: map.observation: expected a mapping"));
}

TEST(ScenarioParse, MissingRequiredKeys) {
  EXPECT_THAT(error_of(replace_line(kMinimal, "name:", "").yaml), HasSubstr("x.yaml:2: name: required key is missing"));
  EXPECT_THAT(error_of(replace_line(kMinimal, "world:", "").yaml), HasSubstr("world: required key is missing"));
  EXPECT_THAT(error_of("name: a\nworld: b\n"), HasSubstr("robot: required mapping is missing"));
  EXPECT_THAT(error_of(replace_line(kMinimal, "  waypoints:", "").yaml),
              HasSubstr("x.yaml:3: robot.waypoints: required key is missing"));
  EXPECT_THAT(error_of(replace_line(kMinimal, "  speed_mps:", "").yaml),
              HasSubstr("robot.speed_mps: required key is missing"));
  EXPECT_THAT(error_of(replace_line(kFull, "  intrinsics:", "  no_intrinsics:").yaml),
              HasSubstr("camera.intrinsics: required mapping is missing"));
  EXPECT_THAT(error_of(replace_line(kFull, "    fy:", "").yaml),
              HasSubstr("camera.intrinsics.fy: required key is missing"));
  EXPECT_THAT(error_of(replace_line(kFull, "      - t: 1.0", "      - tt: 1.0").yaml),
              HasSubstr("moving_bodies[0].keyframes[0].t: required key is missing"));
  EXPECT_THAT(error_of(replace_line(kFull, "  - body:", "  - name: person").yaml),
              HasSubstr("moving_bodies[0].body: required key is missing"));
  EXPECT_THAT(error_of(std::string(kMinimal) + "moving_bodies:\n  - body: person\n"),
              HasSubstr("moving_bodies[0].keyframes: at least one keyframe"));
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
      {"  gl_backend:", "  gl_backend: glx", "camera.gl_backend: unknown GL backend 'glx' (expected auto|egl|osmesa)"},
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

TEST(ScenarioParse, ClearOnNoReturnNeedsRaycastClearing) {
  const std::string frustum = std::string(kMinimal) + "map:\n  observation:\n    clear_on_no_return: true\n";
  EXPECT_THAT(error_of(frustum),
              HasSubstr(at(8, "map.observation.clear_on_no_return") + "needs map.clearing_mode: raycast"));
  const Scenario ok =
      parse(std::string(kMinimal) + "map:\n  clearing_mode: raycast\n  observation:\n    clear_on_no_return: true\n");
  EXPECT_TRUE(ok.camera().sources.front().params.clear_on_no_return);
}

TEST(ScenarioParse, HiddenFalseClearsMaxIsACountOfAtLeastZero) {
  for (const auto& [value, expected] :
       {std::pair<const char*, const char*>{"-1", "must be >= 0"}, {"0.5", "expected an integer"}}) {
    SCOPED_TRACE(value);
    const Edited e = insert_after(kFull, "  accuracy_p90_max_m:", std::string("  hidden_false_clears_max: ") + value);
    EXPECT_THAT(error_of(e.yaml), HasSubstr(at(e.line, "checks.hidden_false_clears_max") + expected));
  }
  const Edited ok = insert_after(kFull, "  accuracy_p90_max_m:", "  hidden_false_clears_max: 0");
  EXPECT_EQ(parse(ok.yaml).checks.hidden_false_clears_max, 0);
}

}  // namespace
}  // namespace stvl::config

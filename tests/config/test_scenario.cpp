#include "config/scenario.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/config/scenario_texts.hpp"

namespace stvl::config {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::MatchesRegex;
using namespace test;

const std::string kScenarioDir = std::string(STVL_SOURCE_DIR) + "/scenarios";

TEST(ScenarioShipped, EveryScenarioInTheFolderLoads) {
  int count = 0;
  std::vector<fs::path> files;  // the shipped scenarios and the sweeps' base files
  for (const auto& dir : {fs::path(kScenarioDir), fs::path(kScenarioDir) / "sweeps"})
    for (const auto& entry : fs::directory_iterator(dir)) files.push_back(entry.path());
  for (const auto& path : files) {
    const fs::directory_entry entry(path);
    if (entry.path().extension() != ".yaml") continue;
    ++count;
    SCOPED_TRACE(entry.path().string());
    Scenario s;
    ASSERT_NO_THROW(s = load_scenario(entry.path().string()));
    EXPECT_EQ(s.name, entry.path().stem().string());
    EXPECT_TRUE(fs::is_regular_file(s.pipeline.world_path)) << s.pipeline.world_path;
    if (s.navigation.mode == navigation::NavigationMode::kClosedLoop)
      EXPECT_TRUE(s.pipeline.path.waypoints_W.empty());  // nav2 drives to navigation.goal
    else EXPECT_GE(s.pipeline.path.waypoints_W.size(), 2u);
    const auto& c = s.checks;
    EXPECT_TRUE(c.f1_3d_min || c.iou_3d_min || c.costmap_precision_min || c.costmap_recall_min ||
                c.all_obstacles_detected || c.phantom_obstacles_max || c.clearing_latency_max_s ||
                c.accuracy_p90_max_m || c.self_lethal_cells_max || c.outage_cleared_max || c.outage_resume_max_s)
        << "a shipped scenario checks nothing";
    // Native scenarios clear with each camera's own FOV (a ROS parameter file gives its own: lint compares).
    if (!s.ros_params) {
      for (const auto& camera : s.pipeline.cameras) {
        EXPECT_DOUBLE_EQ(camera.sources.front().params.horizontal_fov_rad, camera.intrinsics.hfov_rad());
      }
    }
  }
  EXPECT_GE(count, 12);
}

// tests/scenarios/CMakeLists.txt lists the scenarios CI runs by name (no GLOB): a new one must be added there.
TEST(ScenarioShipped, EveryScenarioInTheFolderRunsInCi) {
  std::ifstream in(std::string(STVL_SOURCE_DIR) + "/tests/scenarios/CMakeLists.txt");
  ASSERT_TRUE(in.good());
  const std::string list((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  int count = 0;
  for (const auto& entry : fs::directory_iterator(kScenarioDir)) {
    if (entry.path().extension() != ".yaml") continue;
    ++count;
    EXPECT_THAT(list, HasSubstr(" " + entry.path().stem().string() + "\n"))
        << entry.path().filename() << " is not in tests/scenarios/CMakeLists.txt's scenario list";
  }
  EXPECT_GE(count, 11);
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
  EXPECT_TRUE(s.camera().sources.front().params.marking);
  EXPECT_TRUE(s.camera().sources.front().params.clearing);
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
  EXPECT_TRUE(n.stereo_occlusion);
  EXPECT_DOUBLE_EQ(n.left_band_margin_px, 10.0);
  EXPECT_DOUBLE_EQ(n.left_band_jitter_px, 1.5);
  EXPECT_DOUBLE_EQ(n.shadow_margin_px, 3.0);
  EXPECT_DOUBLE_EQ(n.correlated_fraction, 0.5);
  EXPECT_DOUBLE_EQ(n.correlated_cell_px, 8.0);
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
  const auto& o = s.camera().sources.front().params;
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

TEST(ScenarioParse, FootprintClearingKeys) {
  const Scenario plain = parse(kMinimal);
  EXPECT_TRUE(plain.pipeline.map.update_footprint_enabled);  // STVL's default
  EXPECT_TRUE(plain.pipeline.map.footprint_B.empty());
  EXPECT_TRUE(plain.pipeline.robot_geoms_seen.empty());
  const Scenario round =
      parse(std::string(kMinimal) + "map:\n  update_footprint_enabled: false\n  robot_radius: 0.25\n");
  EXPECT_FALSE(round.pipeline.map.update_footprint_enabled);
  ASSERT_EQ(round.pipeline.map.footprint_B.size(), 16u);
  EXPECT_NEAR(round.pipeline.map.footprint_B[0].x(), 0.25, 1e-12);
  const Scenario polygon = parse(std::string(kMinimal) +
                                 "map:\n  footprint: [[0.3, 0.2], [0.3, -0.2], [-0.2, 0]]\n"
                                 "checks:\n  self_lethal_cells_max: 0\n");
  ASSERT_EQ(polygon.pipeline.map.footprint_B.size(), 3u);
  EXPECT_DOUBLE_EQ(polygon.pipeline.map.footprint_B[1].y(), -0.2);
  EXPECT_EQ(polygon.checks.self_lethal_cells_max, 0);
  EXPECT_EQ(evaluation_config(polygon).robot_footprint_B.size(), 3u);
  EXPECT_TRUE(evaluation_config(polygon).footprint_clearing);
  const std::string base = std::string(kMinimal) + "map:\n";
  EXPECT_THAT(error_of(base + "  robot_radius: -0.1\n"),
              HasSubstr(at(7, "map.robot_radius") + "must be finite and > 0 m"));
  EXPECT_THAT(error_of(base + "  robot_radius: .nan\n"), HasSubstr(at(7, "map.robot_radius")));
  EXPECT_THAT(error_of(base + "  footprint: [[0, 1], [1, 0]]\n"),
              HasSubstr(at(7, "map.footprint") + "needs at least three"));
  EXPECT_THAT(error_of(base + "  footprint: [[0, 1], [1, 0], [0, .inf]]\n"),
              HasSubstr(at(7, "map.footprint") + "points must be finite"));
  EXPECT_THAT(error_of(base + "  footprint: [[0, 1], [1, 0], [0]]\n"), HasSubstr(at(7, "map.footprint")));
  EXPECT_THAT(error_of(base + "  robot_radius: 0.2\n  footprint: [[0, 1], [1, 0], [0, 0]]\n"),
              HasSubstr("give either footprint or robot_radius"));
  EXPECT_THAT(error_of(std::string(kMinimal) + "checks:\n  self_lethal_cells_max: 0\n"),
              HasSubstr(at(7, "checks.self_lethal_cells_max") + "needs the robot's footprint"));
  EXPECT_THAT(error_of(base + "  robot_radius: 0.2\nchecks:\n  self_lethal_cells_max: -1\n"),
              HasSubstr("must be >= 0"));
  // Ours: the voxels inside the footprint up to a height.
  EXPECT_DOUBLE_EQ(plain.pipeline.map.clear_footprint_voxels_below_m, 0.0);  // off
  EXPECT_DOUBLE_EQ(parse(base + "  robot_radius: 0.2\n  clear_footprint_voxels_below: 0.3\n")
                       .pipeline.map.clear_footprint_voxels_below_m,
                   0.3);
  EXPECT_THAT(error_of(base + "  robot_radius: 0.2\n  clear_footprint_voxels_below: -0.3\n"),
              HasSubstr(at(8, "map.clear_footprint_voxels_below") + "must lie in [0, 3] m"));
  EXPECT_THAT(error_of(base + "  clear_footprint_voxels_below: 0.3\n"),
              HasSubstr(at(7, "map.clear_footprint_voxels_below") + "needs the robot's footprint"));
}

TEST(ScenarioParse, PresetsSetTheIntrinsics) {
  const Scenario s = parse(std::string(kMinimal) + "camera: {preset: d435_640x480, rate_hz: 6}\n");
  EXPECT_EQ(s.camera().intrinsics.width, 640);
  EXPECT_EQ(s.camera().intrinsics.height, 480);
  EXPECT_DOUBLE_EQ(s.camera().intrinsics.rate_hz, 6.0);
}

TEST(ScenarioParse, ClearingFrustumFovDefaultsToTheCamera) {
  const Scenario wide = parse(kMinimal);
  EXPECT_DOUBLE_EQ(wide.camera().sources.front().params.horizontal_fov_rad,
                   sensors::CameraIntrinsics::d435_848x480().hfov_rad());
  EXPECT_DOUBLE_EQ(wide.camera().sources.front().params.vertical_fov_rad,
                   sensors::CameraIntrinsics::d435_848x480().vfov_rad());

  const Scenario narrow =
      parse(std::string(kMinimal) + "camera: {preset: d435_640x480}\nmap:\n  observation: {max_z: 4}\n");
  EXPECT_DOUBLE_EQ(narrow.camera().sources.front().params.horizontal_fov_rad,
                   sensors::CameraIntrinsics::d435_640x480().hfov_rad());
  EXPECT_DOUBLE_EQ(narrow.camera().sources.front().params.vertical_fov_rad,
                   sensors::CameraIntrinsics::d435_640x480().vfov_rad());
  EXPECT_LT(narrow.camera().sources.front().params.horizontal_fov_rad,
            wide.camera().sources.front().params.horizontal_fov_rad);
  EXPECT_DOUBLE_EQ(narrow.camera().sources.front().params.max_z_m, 4.0);

  const Scenario custom = parse(replace_line(kFull, "    vertical_fov_angle:", "").yaml);
  EXPECT_DOUBLE_EQ(custom.camera().sources.front().params.horizontal_fov_rad, 1.2);
  EXPECT_DOUBLE_EQ(custom.camera().sources.front().params.vertical_fov_rad, custom.camera().intrinsics.vfov_rad());
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
  EXPECT_THAT(invalid_argument_of([&] { load_scenario(file.string()); }),
              HasSubstr(file.string() + ":6: robot.bogus: unknown key"));
  fs::remove_all(dir);
  EXPECT_THAT(invalid_argument_of([&] { load_scenario(file.string()); }), HasSubstr(file.string() + ": no such file"));
}

TEST(ScenarioParse, SetAssignmentsChangeTheDocumentBeforeItIsRead) {
  const fs::path dir = fs::temp_directory_path() / ("stvl_scenario_set_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path file = dir / "s.yaml";
  std::ofstream(file) << kMinimal;
  const Scenario plain = load_scenario(file.string());
  const Scenario set =
      load_scenario(file.string(), {"duration_s=3.5", "map.voxel_size=0.1", "map.observation.max_z=4"});
  EXPECT_NE(plain.duration_s, 3.5);
  EXPECT_DOUBLE_EQ(set.duration_s, 3.5);
  EXPECT_DOUBLE_EQ(set.pipeline.map.voxel_size_m, 0.1);
  EXPECT_DOUBLE_EQ(set.camera().sources.front().params.max_z_m, 4.0);
  // Errors about a key an assignment set blame the assignment, with the nearest known name.
  EXPECT_THAT(invalid_argument_of([&] { load_scenario(file.string(), {"map.voxel_sze=0.1"}); }),
              HasSubstr("--set map.voxel_sze=0.1: unknown key; did you mean 'voxel_size'?"));
  EXPECT_THAT(invalid_argument_of([&] { load_scenario(file.string(), {"duration_s=[1, 2]"}); }),
              HasSubstr("--set duration_s=[1, 2]: expected a number"));
  fs::remove_all(dir);
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
  cases[8].overrides.gl_backend = "glx", cases[8].expected = "--gl: unknown GL backend 'glx'";
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

// Soak (issue #270): the patrol's loop, the repeating walk and the samples are read; a loop never stops at the end.
TEST(ScenarioParse, SoakPatrolReadsLoopRepeatAndSamples) {
  const Scenario s = load_scenario(std::string(STVL_SOURCE_DIR) + "/tests/scenarios/soak_patrol.yaml");
  EXPECT_TRUE(s.pipeline.path.loop);
  EXPECT_FALSE(s.stop_at_path_end);
  ASSERT_EQ(s.pipeline.moving_bodies.size(), 1u);
  ASSERT_TRUE(s.pipeline.moving_bodies[0].repeat_s.has_value());
  EXPECT_EQ(*s.pipeline.moving_bodies[0].repeat_s, 45.0);
  EXPECT_EQ(s.outputs.soak_sample_every_s, 60.0);
  EXPECT_TRUE(s.checks.soak_rss_growth_max && s.checks.soak_map_ms_growth_max);
  const Scenario plain = parse_scenario(kMinimal, "m.yaml", ".");
  EXPECT_FALSE(plain.pipeline.path.loop);
  EXPECT_TRUE(plain.stop_at_path_end);
  EXPECT_EQ(plain.outputs.soak_sample_every_s, 0.0);
  EXPECT_FALSE(plain.pipeline.moving_bodies.size());
}

}  // namespace
}  // namespace stvl::config

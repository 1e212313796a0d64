#include "config/ros_lint.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <utility>

#include "config/ros_lint_geometry.hpp"
#include "tests/config/ros_texts.hpp"
#include "tests/support/invalid_argument.hpp"

namespace stvl::config {
namespace {

using stvl::test::quoted;
using ::testing::HasSubstr;

// A bare layer (ROS 2's rules) without findings; each test changes one thing.
const std::string kClean =
    "voxel_decay: 15.0\n"            // 1
    "voxel_size: 0.05\n"             // 2
    "observation_sources: cam\n"     // 3
    "cam:\n"                         // 4
    "  clearing: true\n"             // 5
    "  min_obstacle_height: 0.05\n"  // 6
    "  decay_acceleration: 15.0\n";  // 7

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return pos == std::string::npos ? text : text.replace(pos, from.size(), to);
}

// The camera a source is bound to, when lint knows only its FOV (and, for `camera`, which sources share it).
BoundCamera fov_of(const std::string& source, double hfov_rad, double vfov_rad, const std::string& camera = "") {
  BoundCamera bound;
  bound.source = source;
  bound.hfov_rad = hfov_rad;
  bound.vfov_rad = vfov_rad;
  bound.camera = camera;
  return bound;
}

class RosLint : public ::testing::Test {
 protected:
  std::vector<LintFinding> lint(const std::string& text, const std::vector<BoundCamera>& cameras = {}) {
    path_ = test::write_file(dir_, "l" + std::to_string(n_++) + ".yaml", text);
    return lint_ros_stvl_layer(path_, "", "", cameras);
  }
  // The only finding of `text`, as format_finding() writes it.
  std::string only(const std::string& text, const std::vector<BoundCamera>& cameras = {}) {
    const auto findings = lint(text, cameras);
    EXPECT_EQ(findings.size(), 1u);
    std::string all;
    for (const auto& f : findings) all += format_finding(f) + "\n";
    return test::file_as_FILE(findings.size() == 1 ? format_finding(findings[0]) : all, path_);
  }
  static std::string at(int line, const std::string& key) { return "FILE:" + std::to_string(line) + ": " + key + ": "; }
  stvl::test::TempDir dir_{"ros_lint"};
  std::string path_;
  int n_ = 0;
};

TEST_F(RosLint, CleanLayerHasNoFindings) { EXPECT_TRUE(lint(kClean).empty()); }

TEST_F(RosLint, Nav2TutorialYieldsTheKeysRos2DoesNotRead) {
  std::set<std::pair<int, std::string>> found;
  std::set<std::pair<int, std::string>> unread;
  for (const auto& f : lint_ros_stvl_layer(test::kTutorialFile, "")) {
    found.insert({f.line, f.key});
    if (f.what_stvl_does.find("does not read") != std::string::npos ||
        f.what_stvl_does.find("per source only") != std::string::npos ||
        f.what_stvl_does.find("ignores") != std::string::npos)
      unread.insert({f.line, f.key});
  }
  const std::set<std::pair<int, std::string>> expected_unread = {{30, "stvl_layer.max_obstacle_height"},
                                                                 {31, "stvl_layer.unknown_threshold"},
                                                                 {35, "stvl_layer.obstacle_range"},
                                                                 {36, "stvl_layer.origin_z"},
                                                                 {52, "stvl_layer.pointcloud.voxel_filter"}};
  EXPECT_EQ(unread, expected_unread);
  auto expected = expected_unread;
  expected.insert({47, "stvl_layer.pointcloud.min_obstacle_height"});  // the tutorial's 0.0: floor noise marks
  EXPECT_EQ(found, expected);
}

TEST_F(RosLint, KeysStvlDoesNotRead) {
  EXPECT_EQ(only(kClean + "unknown_threshold: 15\n"),
            at(8, "unknown_threshold") +
                "STVL (ROS 2) does not read unknown_threshold (a voxel_layer key); it has "
                "no effect; write instead: remove it");
  EXPECT_EQ(only(kClean + "obstacle_range: 3.0\n"),
            at(8, "obstacle_range") +
                "STVL (ROS 2) reads obstacle_range per source only; this layer-level value "
                "has no effect (a source without its own uses 2.5 m); write instead: obstacle_range: 3.0 under "
                "each source");
  EXPECT_EQ(only(kClean + "  max_zz: 3.0\n"),
            at(8, "cam.max_zz") +
                "STVL (ROS 2) does not read max_zz; it has no effect; write instead: max_z (the "
                "nearest key STVL reads)");
  EXPECT_EQ(only(replaced(kClean, "voxel_size", "voxel_sise")),
            at(2, "voxel_sise") +
                "STVL (ROS 2) does not read voxel_sise; it has no effect; write instead: "
                "voxel_size (the nearest key STVL reads)");
}

TEST_F(RosLint, Ros1ReadsLayerLevelObstacleRange) {
  EXPECT_TRUE(lint(test::ros1_text(kClean + "obstacle_range: 2.0\n")).empty());
}

TEST_F(RosLint, VoxelFilterIsIgnoredByRos2) {
  EXPECT_EQ(only(kClean + "  voxel_filter: true\n"),
            at(8, "cam.voxel_filter") +
                "ROS 2 STVL ignores voxel_filter (ROS 1 melodic's key) and applies `filter` (default passthrough); "
                "voxel_filter: true silently has no effect (STVL issue #188: CPU use exploded); write instead: "
                "filter: \"voxel\"");
  EXPECT_EQ(only(test::ros1_text(kClean + "  voxel_filter: true\n")),
            at(13, "stvl_layer.cam.voxel_filter") +
                "melodic-devel reads voxel_filter, noetic-devel ignores it and applies `filter` (default "
                "passthrough); write instead: also filter: \"voxel\" for noetic");
  EXPECT_TRUE(lint(test::ros1_text(kClean + "  voxel_filter: true\n  filter: voxel\n")).empty());
}

TEST_F(RosLint, DecayModelsStvlTreatsAsPersistent) {
  EXPECT_EQ(only(kClean + "decay_model: 5\n"),
            at(8, "decay_model") +
                "STVL treats decay_model 5 as persistent (every code but 0 and 1): voxels never "
                "expire, only frustum acceleration removes them; write instead: decay_model: 0 "
                "(linear) or 1 (exponential) for voxels to expire; -1, as STVL's README "
                "documents, if persistence is meant");
  EXPECT_TRUE(lint(kClean + "decay_model: 1\n").empty());
}

TEST_F(RosLint, MaxZBelowObstacleRange) {
  EXPECT_EQ(only(kClean + "  obstacle_range: 4.0\n  max_z: 3.0\n"),
            at(9, "cam.max_z") +
                "max_z = 3 m with obstacle_range = 4 m: STVL's depth-camera frustum puts its far "
                "plane at max_z·cos(h/2)·cos(v/2) = 3 × cos(0.52) × cos(0.35) = 2.45 m along the "
                "optical axis, not at max_z: voxels marked between 2.45 and 4 m are never reached "
                "by frustum acceleration (decay_acceleration), only voxel_decay removes them; write "
                "instead: max_z: 4.91 (obstacle_range / (cos(h/2)·cos(v/2))), or obstacle_range: 2.44");
}

TEST_F(RosLint, FarPlaneIsNotMaxZ) {
  // max_z above obstacle_range is not enough: the far plane lies at 3.5 cos(0.52) cos(0.35) = 2.85 m.
  EXPECT_THAT(only(kClean + "  obstacle_range: 3.0\n  max_z: 3.5\n"),
              HasSubstr(at(9, "cam.max_z") + "max_z = 3.5 m with obstacle_range = 3 m: STVL's depth-camera frustum "
                                             "puts its far plane at max_z·cos(h/2)·cos(v/2) = 3.5 × cos(0.52) × "
                                             "cos(0.35) = 2.85 m"));
  EXPECT_TRUE(lint(kClean + "  obstacle_range: 3.0\n  max_z: 3.7\n").empty());  // far plane 3.02 m
  // A source that does not clear has no frustum: its max_z says nothing.
  EXPECT_TRUE(lint(replaced(kClean, "sources: cam", "sources: cam other") +
                   "other:\n  min_obstacle_height: 0.05\n  obstacle_range: 4.0\n  max_z: 3.0\n")
                  .empty());
}

TEST_F(RosLint, FovOffTheBoundCamera) {
  const std::string text = kClean + "  horizontal_fov_angle: 1.5\n";
  EXPECT_TRUE(lint(text).empty());                              // no camera bound: nothing to compare with
  EXPECT_TRUE(lint(text, {fov_of("cam", 1.46, 0.7)}).empty());  // within 5 %
  EXPECT_EQ(only(text, {fov_of("cam", 1.2, 0.7)}),
            at(8, "cam.horizontal_fov_angle") +
                "horizontal_fov_angle = 1.5 rad is more than 5 % off the bound "
                "camera's 1.2 rad: STVL's clearing frustum clears voxels the camera "
                "cannot see; write instead: horizontal_fov_angle: 1.2");
  EXPECT_EQ(only(text, {fov_of("cam", 1.5, 0.9)}),
            at(4, "cam.vertical_fov_angle") +
                "vertical_fov_angle = 0.7 rad is more than 5 % off the bound camera's "
                "0.9 rad: STVL's clearing frustum leaves the edges of the view "
                "uncleared; write instead: vertical_fov_angle: 0.9");
}

TEST_F(RosLint, NoFovFindingForASourceThatDoesNotClear) {
  const std::string marking_only =
      replaced(kClean, "  clearing: true\n", "  clearing: false\n") + "  horizontal_fov_angle: 1.5\n";
  const auto findings = lint(marking_only, {fov_of("cam", 1.2, 0.9)});
  ASSERT_EQ(findings.size(), 1u);  // the layer's: no source clears
  EXPECT_EQ(findings[0].key, "observation_sources");
}

TEST_F(RosLint, MinObstacleHeightAtTheFloor) {
  EXPECT_EQ(only(replaced(kClean, "min_obstacle_height: 0.05", "min_obstacle_height: 0.0")),
            at(6, "cam.min_obstacle_height") +
                "min_obstacle_height = 0 m: STVL marks points at floor level, so the "
                "depth camera's floor noise becomes obstacles; write instead: "
                "min_obstacle_height: 0.05 (above the floor noise)");
}

// A nav2 layer with one camera's marking and clearing sources, as nav2's STVL configurations write the pair
// (both read the camera's topic; layer body from line 8).
const std::string kMarkAndClear =
    "voxel_decay: 15.0\n"                            // 8
    "voxel_size: 0.05\n"                             // 9
    "observation_sources: rgbd1_mark rgbd1_clear\n"  // 10
    "rgbd1_mark:\n"                                  // 11
    "  data_type: PointCloud2\n"                     // 12
    "  topic: /input_pointcloud\n"                   // 13
    "  marking: true\n"                              // 14
    "  clearing: false\n"                            // 15
    "  obstacle_range: 3.0\n"                        // 16
    "  min_obstacle_height: 0.02\n"                  // 17
    "  max_obstacle_height: 2.0\n"                   // 18
    "  filter: \"passthrough\"\n"                    // 19
    "rgbd1_clear:\n"                                 // 20
    "  data_type: PointCloud2\n"                     // 21
    "  topic: /input_pointcloud\n"                   // 22
    "  marking: false\n"                             // 23
    "  clearing: true\n"                             // 24
    "  max_z: 7.0\n"                                 // 25
    "  min_z: 0.02\n"                                // 26
    "  vertical_fov_angle: 0.8745\n"                 // 27
    "  horizontal_fov_angle: 1.048\n"                // 28
    "  decay_acceleration: 15.0\n"                   // 29
    "  model_type: 0\n";                             // 30

TEST_F(RosLint, MarkingSourcePastTheClearingSourcesFarPlane) {
  EXPECT_TRUE(lint(test::nav2_text(kMarkAndClear)).empty());  // far plane 5.49 m, obstacle_range 3 m
  EXPECT_EQ(only(test::nav2_text(replaced(kMarkAndClear, "obstacle_range: 3.0", "obstacle_range: 6.0"))),
            at(16, "stvl_layer.rgbd1_mark.obstacle_range") +
                "obstacle_range = 6 m marks past the clearing frustum of rgbd1_clear (line 20), the same camera's "
                "source reaching farthest: STVL's depth-camera frustum puts its far plane at max_z·cos(h/2)·cos(v/2) "
                "= 7 × cos(0.524) × cos(0.43725) = 5.49 m along the optical axis, not at max_z: voxels marked "
                "between 5.49 and 6 m are never reached by frustum acceleration (decay_acceleration), only "
                "voxel_decay removes them; write instead: max_z: 7.65 on rgbd1_clear (obstacle_range / "
                "(cos(h/2)·cos(v/2))), or obstacle_range: 5.49");
  // max_z 3.5 >= obstacle_range 3, but its far plane lies at 2.75 m.
  EXPECT_THAT(only(test::nav2_text(replaced(kMarkAndClear, "max_z: 7.0", "max_z: 3.5"))),
              HasSubstr(at(16, "stvl_layer.rgbd1_mark.obstacle_range") + "obstacle_range = 3 m marks past the "
                                                                         "clearing frustum of rgbd1_clear (line 20)"));
  // A clearing source of another camera (topic) clears nothing of this one's marks.
  EXPECT_TRUE(lint(test::nav2_text(replaced(replaced(kMarkAndClear, "obstacle_range: 3.0", "obstacle_range: 6.0"),
                                            "  topic: /input_pointcloud\n  marking: false",
                                            "  topic: /other/points\n  marking: false")))
                  .empty());
  // Bound to different cameras at run time: no longer one camera's sources.
  EXPECT_TRUE(lint(test::nav2_text(replaced(kMarkAndClear, "obstacle_range: 3.0", "obstacle_range: 6.0")),
                   {fov_of("rgbd1_mark", 1.048, 0.8745, "left"), fov_of("rgbd1_clear", 1.048, 0.8745, "right")})
                  .empty());
}

TEST_F(RosLint, HeightsMarkedButNeverCleared) {
  // A camera 0.5 m above the floor pitched 0.3 rad down with a 1.0 rad vertical FOV sees up to
  // 0.5 + 3 sin(0.5 - 0.3) = 1.10 m within obstacle_range 3; a clearing frustum of 0.6 rad tops out at 0.5 m.
  const std::string text =
      test::nav2_text(replaced(kMarkAndClear, "vertical_fov_angle: 0.8745", "vertical_fov_angle: 0.6"));
  const std::vector<BoundCamera> front = {{"rgbd1_mark", 1.048, 1.0, "front", 0.5, 0.3, 0.0, 10.0},
                                          {"rgbd1_clear", 1.048, 1.0, "front", 0.5, 0.3, 0.0, 10.0}};
  const auto findings = lint(text, front);
  ASSERT_EQ(findings.size(), 2u);
  EXPECT_EQ(test::file_as_FILE(format_finding(findings[0]), path_),
            at(18, "stvl_layer.rgbd1_mark.max_obstacle_height") +
                "heights 0.5..1.1 m (world z) are marked but never cleared: camera front (0.5 m above the floor, "
                "pitch 17.19 deg) sees them within obstacle_range = 3 m, and no clearing frustum of it (STVL's: "
                "rgbd1_clear z -2.92..0.5 m) contains them at any distance or robot pose: those voxels leave only "
                "by voxel_decay; write instead: max_obstacle_height: 0.5, or widen the clearing source's "
                "vertical_fov_angle / raise its max_z");
  EXPECT_EQ(findings[1].key, "stvl_layer.rgbd1_clear.vertical_fov_angle");  // 0.6 rad on a 1.0 rad camera
  // The band kept below the frustum's top: only the FOV finding remains.
  EXPECT_EQ(lint(replaced(text, "max_obstacle_height: 2.0", "max_obstacle_height: 0.5"), front).size(), 1u);
  // Without a mount (lint from the command line) heights are not judged.
  EXPECT_EQ(lint(text, {fov_of("rgbd1_mark", 1.048, 1.0), fov_of("rgbd1_clear", 1.048, 1.0)}).size(), 1u);
}

TEST_F(RosLint, StvlFrustumGeometry) {
  namespace geo = lint_geometry;
  EXPECT_NEAR(geo::stvl_plane_depth(7.0, 1.04, 0.7), 5.7064, 1e-4);  // /work/notes: h 1.04, v 0.7, max_z 7
  EXPECT_NEAR(geo::stvl_radial_for_depth(geo::stvl_plane_depth(7.0, 1.04, 0.7), 1.04, 0.7), 7.0, 1e-12);
  // Level camera: the top far corners at 0.5 + 7 cos(h/2) sin(v/2).
  const auto level = geo::stvl_frustum_heights({0.5, 0.0, 0.0}, 0.0, 7.0, 1.04, 0.7);
  EXPECT_NEAR(level.max_m, 0.5 + 7.0 * std::cos(0.52) * std::sin(0.35), 1e-12);
  EXPECT_NEAR(level.min_m, 0.5 - 7.0 * std::cos(0.52) * std::sin(0.35), 1e-12);
  // The ideal view: the top edge's centre 0.2 rad above the horizon; pitched past v/2, nothing above the camera.
  const auto view = geo::view_heights({0.5, 0.3, 0.0}, 1.048, 1.0, 3.0);
  EXPECT_NEAR(view.max_m, 0.5 + 3.0 * std::sin(0.2), 1e-9);
  EXPECT_NEAR(view.min_m, 0.5 - 3.0 * std::sin(0.8), 1e-9);
  EXPECT_NEAR(geo::view_heights({0.5, 0.8, 0.0}, 1.048, 1.0, 3.0).max_m, 0.5, 1e-12);
  // Rolled a quarter turn, the horizontal FOV spans the heights.
  EXPECT_NEAR(geo::view_heights({0.5, 0.0, M_PI / 2}, 1.048, 1.0, 3.0).max_m, 0.5 + 3.0 * std::sin(0.524), 1e-9);
  const auto left = geo::uncovered({0.0, 2.0}, {{-1.0, 0.5}, {1.0, 1.02}}, 0.05);
  ASSERT_EQ(left.size(), 2u);
  EXPECT_DOUBLE_EQ(left[0].min_m, 0.5);
  EXPECT_DOUBLE_EQ(left[0].max_m, 1.0);
  EXPECT_DOUBLE_EQ(left[1].min_m, 1.02);
}

TEST_F(RosLint, NoClearingSource) {
  EXPECT_EQ(only(replaced(replaced(kClean, "  clearing: true\n", ""), "  decay_acceleration: 15.0\n", "")),
            at(3, "observation_sources") +
                "no source has clearing: true (STVL's default is false): voxels leave "
                "only by voxel_decay; write instead: clearing: true on the depth "
                "camera's source");
}

TEST_F(RosLint, VoxelSizeDiffersFromResolution) {
  EXPECT_EQ(only(test::nav2_text(replaced(kClean, "voxel_size: 0.05", "voxel_size: 0.1"))),
            at(9, "stvl_layer.voxel_size") +
                "voxel_size = 0.1 m differs from the costmap's resolution = 0.05 m: "
                "STVL projects voxel columns onto cells of another size; write "
                "instead: voxel_size: 0.05");
}

TEST_F(RosLint, DecayAccelerationZeroOnAClearingSource) {
  EXPECT_EQ(only(replaced(kClean, "decay_acceleration: 15.0", "decay_acceleration: 0.0")),
            at(7, "cam.decay_acceleration") +
                "decay_acceleration = 0 on a clearing source: the frustum does not "
                "speed up decay, only voxel_decay clears; write instead: "
                "decay_acceleration: 15.0 (STVL's example)");
}

TEST_F(RosLint, IntegerForADoubleInRos2) {
  EXPECT_EQ(only(test::nav2_text(replaced(kClean, "voxel_decay: 15.0", "voxel_decay: 15"))),
            at(8, "stvl_layer.voxel_decay") +
                "STVL declares voxel_decay a double and rclcpp (Galactic and later) "
                "rejects the integer 15: the layer fails to load; write instead: "
                "voxel_decay: 15.0");
  EXPECT_TRUE(lint(test::ros1_text(replaced(kClean, "voxel_decay: 15.0", "voxel_decay: 15"))).empty());
}

// STVL's lidar model (x forward, z up) on a depth camera's cloud frame clears beside the view; in the camera's
// link frame it is fine, and its FOV (a full circle here) is not held against the camera's.
TEST_F(RosLint, LidarModelInAnOpticalFrameIsAFinding) {
  const std::string lidar = kClean + "  model_type: 1\n  horizontal_fov_angle: 6.2832\n";
  EXPECT_THAT(only(lidar, {fov_of("cam", 1.5, 1.0)}),
              HasSubstr(at(8, "cam.model_type") + "model_type = 1 builds STVL's 3D lidar model"));
  EXPECT_THAT(only(lidar + "  sensor_frame: front_depth_optical_frame\n"), HasSubstr("sensor_frame: <camera>_link"));
  EXPECT_TRUE(lint(lidar + "  sensor_frame: front_link\n", {fov_of("cam", 1.5, 1.0)}).empty());
  // The depth camera's frustum in a frame that is not optical by its name looks along that frame's z.
  EXPECT_THAT(only(kClean + "  sensor_frame: front_link\n"), HasSubstr("the frustum looks at the ceiling"));
  EXPECT_TRUE(lint(kClean + "  sensor_frame: front_depth_optical_frame\n").empty());
}

// A filter string STVL does not know means no filter at all; "none" and "" say so on purpose.
TEST_F(RosLint, AnUnknownFilterStringIsAFinding) {
  EXPECT_THAT(only(kClean + "  filter: passthrough_relativ\n"),
              HasSubstr(at(8, "cam.filter") + "filter = 'passthrough_relativ': STVL"));
  // The relative filters are the ros2 branch's (PR #304); noetic-devel applies no filter for them.
  EXPECT_TRUE(lint(kClean + "  filter: passthrough_relative\n").empty());
  EXPECT_TRUE(lint(kClean + "  filter: voxel_relative\n  z_reference_frame: base_link\n").empty());
  EXPECT_THAT(only(test::ros1_text(kClean + "  filter: voxel_relative\n")),
              HasSubstr("noetic-devel does not know them"));
  // z_reference_frame does nothing for the other filters.
  EXPECT_THAT(only(kClean + "  filter: passthrough\n  z_reference_frame: base_link\n"),
              HasSubstr(at(9, "cam.z_reference_frame") + "z_reference_frame = 'base_link' has no effect with filter "
                                                         "'passthrough'"));
  EXPECT_TRUE(lint(kClean + "  filter: none\n").empty());
  EXPECT_TRUE(lint(kClean + "  filter: voxel\n").empty());
}

TEST_F(RosLint, NegativeVoxelDecayIsAFinding) {
  EXPECT_EQ(only(replaced(kClean, "voxel_decay: 15.0\n", "")),
            at(1, "voxel_decay") +
                "voxel_decay = -1 (STVL's default): every voxel is removed at the next update, "
                "before the costmap is built, so the layer never marks a cell; write instead: "
                "voxel_decay: 15.0 (STVL's example)");
}

TEST_F(RosLint, ErrorsStayErrors) {
  EXPECT_THAT(test::invalid_argument_of([&] { lint(kClean + "  model_type: 2\n"); }),
              HasSubstr(":8: cam.model_type: 2: STVL knows 0 (depth camera) and 1 (3D lidar)"));
}

TEST_F(RosLint, CommandExitCodes) {
  const auto binary = stvl::test::stvl_bench_binary();
  if (binary.empty()) GTEST_SKIP() << "stvl-bench not built";
  const auto run = [&](const std::string& args) {
    return stvl::test::run_shell(quoted(binary.string()) + " lint " + args);
  };
  const auto tutorial = run(quoted(test::kTutorialFile) + " --costmap local_costmap");
  EXPECT_EQ(tutorial.exit_code, 1) << tutorial.output;
  EXPECT_THAT(tutorial.output, HasSubstr("nav2_stvl_tutorial.yaml:31: stvl_layer.unknown_threshold: "));
  EXPECT_THAT(tutorial.output, HasSubstr("6 findings on stvl_layer in local_costmap (ROS 2 (nav2))"));
  const auto clean = run(quoted(test::write_file(dir_, "clean.yaml", kClean)));
  EXPECT_EQ(clean.exit_code, 0) << clean.output;
  EXPECT_THAT(clean.output, HasSubstr("0 findings"));
  const auto missing = run(quoted(test::kTutorialFile) + " --layer nope");
  EXPECT_EQ(missing.exit_code, 2) << missing.output;
  EXPECT_THAT(missing.output, HasSubstr("local_costmap.plugins: no layer 'nope'"));
  EXPECT_EQ(run(quoted(test::write_file(dir_, "bad.yaml", "a: [1\n"))).exit_code, 2);
}

}  // namespace
}  // namespace stvl::config

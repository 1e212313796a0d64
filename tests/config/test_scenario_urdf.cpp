// robot.urdf: the robot from a URDF, its cameras at URDF links, its footprint, and the errors of those keys.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "sim/urdf_robot.hpp"
#include "tests/config/scenario_texts.hpp"
#include "tests/robot_description/urdf_texts.hpp"

namespace stvl::config {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;
using namespace test;

// The shipped scenarios' folder: ../worlds/urdf/example_bot resolves from there.
std::string scenarios_dir() { return std::filesystem::path(default_scenario_path()).parent_path().string(); }

Scenario parse_here(const std::string& yaml) { return parse_scenario(yaml, "x.yaml", scenarios_dir()); }
std::string error_here(const std::string& yaml) {
  return invalid_argument_of([&] { parse_here(yaml); });
}

const std::string kUrdfRobot = R"(name: urdf
world: ../worlds/office_corridor.xml
robot:
  urdf: ../worlds/urdf/example_bot/example_bot.urdf
  package_path: [../worlds/urdf]
  drive: kinematic
  waypoints: [[0, 0], [1, 0]]
  speed_mps: 0.5
  cameras:
    - name: front
      frame: camera_depth_optical_frame
    - name: mast
      frame: mast_link
)";

TEST(ScenarioUrdf, BuildsTheRobotAndMountsCamerasAtItsLinks) {
  const Scenario s = parse_here(kUrdfRobot);
  ASSERT_TRUE(s.pipeline.urdf_robot);
  const sim::UrdfRobot& robot = *s.pipeline.urdf_robot;
  EXPECT_EQ(robot.urdf.name, "example_bot");
  EXPECT_EQ(robot.drive, sim::DriveMode::kKinematic);
  EXPECT_EQ(s.pipeline.sim.drive, sim::DriveMode::kKinematic);
  EXPECT_EQ(s.pipeline.sim.robot.base_body, "base_footprint");
  EXPECT_EQ(s.pipeline.sim.robot.left_joint, "wheel_left_joint");
  EXPECT_DOUBLE_EQ(s.pipeline.sim.robot.wheel_radius_m, 0.05);
  ASSERT_EQ(s.pipeline.cameras.size(), 2u);
  // The optical frame as the camera's optical frame: camera_link 0.49 m up, pitched down 0.1 rad.
  const auto& front = s.pipeline.cameras[0];
  EXPECT_EQ(front.frame, "camera_depth_optical_frame");
  EXPECT_NEAR(front.mount.height_m, 0.49, 1e-12);
  EXPECT_NEAR(front.mount.forward_offset_m, 0.16, 1e-12);
  EXPECT_NEAR(front.mount.pitch_rad, 0.1, 1e-12);
  // Any other link as a camera_link: the mast's centre, looking along its x.
  const auto& mast = s.pipeline.cameras[1];
  EXPECT_NEAR(mast.mount.height_m, 0.33, 1e-12);
  EXPECT_NEAR(mast.mount.pitch_rad, 0.0, 1e-12);
  EXPECT_THAT(s.camera_mount_locations[0], StartsWith("x.yaml:11: robot.cameras[0].frame"));
  // No footprint in the file: the collision shapes' outline.
  EXPECT_EQ(s.footprint_source, "URDF collision shapes (" + robot.config.urdf + ")");
  EXPECT_EQ(s.pipeline.map.footprint_B, robot.footprint_B);
  EXPECT_GE(s.pipeline.map.footprint_B.size(), 3u);
}

TEST(ScenarioUrdf, TheScenariosFootprintWins) {
  const Scenario s = parse_here(kUrdfRobot + "map:\n  robot_radius: 0.3\n");
  EXPECT_EQ(s.footprint_source, "map.robot_radius");
  EXPECT_EQ(s.pipeline.map.footprint_B.size(), 16u);
  EXPECT_EQ(parse(kMinimal).footprint_source, "");
}

TEST(ScenarioUrdf, KeysThatNeedTheUrdf) {
  EXPECT_THAT(error_of(std::string(kMinimal) + "  drive: kinematic\n"),
              HasSubstr("x.yaml:6: robot.drive: needs robot.urdf (the robot's URDF file)"));
  const std::string framed = std::string(kMinimal) + "  cameras:\n    - name: c\n      frame: camera_link\n";
  EXPECT_THAT(error_of(framed), HasSubstr("x.yaml:8: robot.cameras[0].frame: needs robot.urdf"));
}

TEST(ScenarioUrdf, BadKeysNameTheirLine) {
  EXPECT_THAT(
      error_here(replace_line(kUrdfRobot, "      frame: mast_link", "      frame: mast").yaml),
      HasSubstr("x.yaml:13: robot.cameras[1].frame: " + std::filesystem::path(scenarios_dir()).parent_path().string() +
                "/worlds/urdf/example_bot/example_bot.urdf: no link named 'mast' (links, nearest first: "
                "mast_link, "));
  EXPECT_THAT(error_here(insert_after(kUrdfRobot, "      frame: mast_link", "      mount: {xyz_m: [0, 0, 1]}").yaml),
              HasSubstr("robot.cameras[1].mount: give frame or mount, not both"));
  EXPECT_THAT(
      error_here(replace_line(kUrdfRobot, "  drive: kinematic", "  drive: kinematics").yaml),
      HasSubstr("x.yaml:6: robot.drive: unknown drive 'kinematics' (expected physics|kinematic|auto; did you mean "
                "'kinematic'?)"));
  EXPECT_THAT(error_here(insert_after(kUrdfRobot, "  drive: kinematic", "  wheels: {left: wheel_left_joint}").yaml),
              HasSubstr("robot.wheels.left: name both wheel joints, left and right"));
  EXPECT_THAT(
      error_here(replace_line(kUrdfRobot, "  package_path: [../worlds/urdf]", "  package_path: [nowhere]").yaml),
      HasSubstr("x.yaml:5: robot.package_path: no folder " + scenarios_dir() + "/nowhere"));
  // Without the package path the URDF's package:// mesh is not found: the URDF's own file and line, and the fix.
  EXPECT_THAT(
      error_here(replace_line(kUrdfRobot, "  package_path: [../worlds/urdf]", "").yaml),
      HasSubstr("example_bot.urdf:27: link 'base_link': mesh file 'package://example_bot/meshes/base.obj' names "
                "package 'example_bot' but robot.package_path is empty"));
}

TEST(ScenarioUrdf, TheUrdfsOwnErrorsKeepItsFileAndLine) {
  stvl::test::TempFolder dir;
  const std::string urdf = dir.write("bot.urdf", "<robot name=\"b\">\n<link name=\"a\">\n</robot>\n");
  const std::string yaml =
      replace_line(kUrdfRobot, "  urdf: ../worlds/urdf/example_bot/example_bot.urdf", "  urdf: " + urdf).yaml;
  EXPECT_THAT(error_here(yaml), HasSubstr("x.yaml:4: robot.urdf: " + urdf + ":2: malformed XML: "));
}

}  // namespace
}  // namespace stvl::config

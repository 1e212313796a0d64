// A scenario's nav2_map: the world built in memory from a nav2 map, robot.waypoints planned on it when left out,
// and the errors (both world and nav2_map, a bad map) naming the file, line and key.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "config/scenario.hpp"
#include "pipeline/pipeline.hpp"

namespace stvl::config {
namespace {

using ::testing::HasSubstr;

const std::string kWorlds = std::string(STVL_SOURCE_DIR) + "/worlds";
const std::string kRobot = "robot:\n  speed_mps: 0.6\n";

std::string error_of(const std::string& yaml) {
  try {
    parse_scenario(yaml, "map.yaml", kWorlds);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(ScenarioMap, WorldIsBuiltInMemoryAndThePathPlannedOnTheMap) {
  const Scenario s =
      parse_scenario("name: m\nnav2_map: {file: maps/office_floor.yaml}\n" + kRobot, "map.yaml", kWorlds);
  EXPECT_EQ(s.pipeline.world_path, kWorlds + "/maps/office_floor.yaml");
  EXPECT_THAT(s.pipeline.world_xml, HasSubstr("<include file=\"robot.xml\"/>"));
  EXPECT_EQ(s.pipeline.world_include_dir, kWorlds);
  const auto& w = s.pipeline.path.waypoints_W;
  ASSERT_GE(w.size(), 2u);
  EXPECT_DOUBLE_EQ(s.pipeline.start_pose.x_m, w.front().x());  // the robot starts at the path's first point,
  EXPECT_NEAR(s.pipeline.start_pose.yaw_rad, std::atan2(w[1].y() - w[0].y(), w[1].x() - w[0].x()), 1e-12);  // facing it
  EXPECT_GT(s.duration_s, 8.0 / 0.6);                     // from the planned path, not the 30 s default
  const auto sim = pipeline::make_simulator(s.pipeline);  // MuJoCo loads the world through its virtual file system
  EXPECT_GT(sim->world().model()->ngeom, 20);
}

TEST(ScenarioMap, GivenStartWaypointsAndDurationAreKept) {
  const Scenario from_start = parse_scenario(
      "name: m\nnav2_map: {file: maps/office_floor.yaml, wall_height_m: 2}\nduration_s: 99\n"
      "robot:\n  start: [-0.3, 1.0, 0]\n  speed_mps: 0.6\n",
      "map.yaml", kWorlds);
  EXPECT_EQ(from_start.pipeline.path.waypoints_W.front(), Eigen::Vector2d(-0.3, 1.0));
  EXPECT_DOUBLE_EQ(from_start.duration_s, 99.0);
  EXPECT_THAT(from_start.pipeline.world_xml, HasSubstr("size=\"5.0000 0.0500 1.0000\""));  // 2 m walls
  const Scenario given = parse_scenario(
      "name: m\nnav2_map: {file: maps/office_floor.yaml}\n"
      "robot:\n  waypoints: [[-0.3, 1.0], [7.5, 1.0]]\n  speed_mps: 0.6\n",
      "map.yaml", kWorlds);
  EXPECT_EQ(given.pipeline.path.waypoints_W.size(), 2u);
  EXPECT_DOUBLE_EQ(given.duration_s, 30.0);
}

TEST(ScenarioMap, AUrdfRobotIsPlannedForWithItsOwnFootprintAndLoadsIntoTheMapWorld) {
  const Scenario s = parse_scenario(
      "name: m\nnav2_map: {file: maps/office_floor.yaml}\nrobot:\n"
      "  urdf: urdf/example_bot/example_bot.urdf\n  package_path: [urdf]\n  drive: kinematic\n"
      "  speed_mps: 0.6\n  cameras:\n    - {name: camera, frame: camera_depth_optical_frame}\n",
      "map.yaml", kWorlds);
  ASSERT_TRUE(s.pipeline.urdf_robot);
  EXPECT_GE(s.pipeline.path.waypoints_W.size(), 2u);
  const auto sim = pipeline::make_simulator(s.pipeline);  // the URDF robot in place of robot.xml, through the VFS
  EXPECT_GE(sim->world().model()->nbody, 3);
}

TEST(ScenarioMap, ErrorsNameTheFileLineAndKey) {
  EXPECT_THAT(error_of("name: m\nworld: office_corridor.xml\nnav2_map: {file: maps/office_floor.yaml}\n" + kRobot),
              HasSubstr("map.yaml:3: nav2_map: give either world (an MJCF file) or nav2_map"));
  EXPECT_THAT(error_of("name: m\nnav2_map: {file: maps/none.yaml}\n" + kRobot),
              HasSubstr("map.yaml:2: nav2_map.file: " + kWorlds + "/maps/none.yaml: cannot read the map's YAML file"));
  EXPECT_THAT(error_of("name: m\nnav2_map: {file: maps/office_floor.yaml, wall_hieght_m: 2}\n" + kRobot),
              HasSubstr("nav2_map.wall_hieght_m: unknown key; did you mean 'wall_height_m'?"));
  EXPECT_THAT(
      error_of(
          "name: m\nnav2_map: {file: maps/office_floor.yaml}\nrobot:\n  start: [1.0, 0.15, 0]\n  speed_mps: 0.6\n"),
      HasSubstr("map.yaml:4: robot.start: planning robot.waypoints on"));
  EXPECT_THAT(error_of("name: m\n" + kRobot), HasSubstr("world: required key is missing"));
}

}  // namespace
}  // namespace stvl::config

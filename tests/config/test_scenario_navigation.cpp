// A scenario's navigation section (issue 41): the mode, the goal (given, or the waypoints' end), nav2's keys per
// server with their defaults, the drive's checks, and the errors naming the file, line and key.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "config/scenario.hpp"
#include "tests/config/scenario_texts.hpp"

namespace stvl::config {
namespace {

using ::testing::HasSubstr;
using namespace test;

const char* const kClosedLoop = R"(name: closed
world: w.xml
robot:
  start: [0, 0, 0]
navigation:
  mode: closed_loop
  goal: [5, 1, 90]
  robot_radius: 0.25
)";

TEST(ScenarioNavigation, PathIsTheDefault) {
  const Scenario s = parse(kMinimal);
  EXPECT_EQ(s.navigation.mode, navigation::NavigationMode::kPath);
  EXPECT_EQ(s.pipeline.path.waypoints_W.size(), 2u);
}

TEST(ScenarioNavigation, ClosedLoopNeedsNoWaypointsAndTakesNav2sDefaults) {
  const Scenario s = parse(kClosedLoop);
  const navigation::NavigationConfig& n = s.navigation;
  EXPECT_EQ(n.mode, navigation::NavigationMode::kClosedLoop);
  EXPECT_DOUBLE_EQ(n.goal.x_m, 5.0);
  EXPECT_NEAR(n.goal.yaw_rad, M_PI / 2, 1e-12);  // degrees in the file, as robot.start
  EXPECT_DOUBLE_EQ(n.robot_radius_m, 0.25);
  EXPECT_TRUE(s.pipeline.path.waypoints_W.empty());
  EXPECT_FALSE(s.stop_at_path_end);
  // nav2_bringup's nav2_params.yaml (jazzy f4108e5)
  EXPECT_DOUBLE_EQ(n.controller_frequency_hz, 20.0);
  EXPECT_DOUBLE_EQ(n.failure_tolerance_s, 0.3);
  EXPECT_DOUBLE_EQ(n.local_costmap.width_m, 3.0);
  EXPECT_DOUBLE_EQ(n.local_costmap.update_frequency_hz, 5.0);
  EXPECT_FALSE(n.local_costmap.track_unknown_space);
  EXPECT_TRUE(n.global_costmap.track_unknown_space);
  EXPECT_DOUBLE_EQ(n.global_costmap.update_frequency_hz, 1.0);
  EXPECT_DOUBLE_EQ(n.planner.tolerance_m, 0.5);
  EXPECT_FALSE(n.planner.use_astar);
  EXPECT_EQ(n.number_of_retries, 6);
  EXPECT_DOUBLE_EQ(n.behaviors.spin_dist_rad, 1.57);
}

TEST(ScenarioNavigation, TheGoalDefaultsToTheLastWaypointAlongTheLastLeg) {
  const Scenario s = parse(R"(name: closed
world: w.xml
robot:
  waypoints: [[0, 0], [3, 0], [3, 4]]
navigation: {mode: closed_loop, robot_radius: 0.3}
)");
  EXPECT_DOUBLE_EQ(s.navigation.goal.x_m, 3.0);
  EXPECT_DOUBLE_EQ(s.navigation.goal.y_m, 4.0);
  EXPECT_NEAR(s.navigation.goal.yaw_rad, M_PI / 2, 1e-12);
  EXPECT_TRUE(s.pipeline.path.waypoints_W.empty());  // nothing to follow: nav2 drives
}

TEST(ScenarioNavigation, ServersKeysAreRead) {
  const Scenario s = parse(std::string(kClosedLoop) + R"(  replan_frequency: 2.0
  number_of_retries: 3
  local_costmap:
    width: 4
    resolution: 0.1
    inflation_layer: {inflation_radius: 0.9, cost_scaling_factor: 2.5}
  global_costmap: {update_frequency: 0.5}
  planner: {tolerance: 0.0, use_astar: true}
  goal_checker: {xy_goal_tolerance: 0.1}
  progress_checker: {movement_time_allowance: 5.0}
  behaviors: {spin_dist: 3.14, wait_duration: 1.0}
checks:
  navigation_success: true
  collisions_max: 0
  time_to_goal_max_s: 60
  recoveries_max: 2
  blocked_time_max_s: 5
)");
  const navigation::NavigationConfig& n = s.navigation;
  EXPECT_DOUBLE_EQ(n.replan_frequency_hz, 2.0);
  EXPECT_EQ(n.number_of_retries, 3);
  EXPECT_DOUBLE_EQ(n.local_costmap.width_m, 4.0);
  EXPECT_DOUBLE_EQ(n.local_costmap.resolution_m, 0.1);
  EXPECT_DOUBLE_EQ(n.local_costmap.inflation.inflation_radius_m, 0.9);
  EXPECT_DOUBLE_EQ(n.local_costmap.inflation.cost_scaling_factor, 2.5);
  EXPECT_DOUBLE_EQ(n.global_costmap.update_frequency_hz, 0.5);
  EXPECT_TRUE(n.planner.use_astar);
  EXPECT_DOUBLE_EQ(n.planner.tolerance_m, 0.0);
  EXPECT_DOUBLE_EQ(n.goal_checker.xy_goal_tolerance, 0.1);
  EXPECT_DOUBLE_EQ(n.progress_checker.movement_time_allowance, 5.0);
  EXPECT_DOUBLE_EQ(n.behaviors.spin_dist_rad, 3.14);
  EXPECT_TRUE(s.checks.navigation_success);
  EXPECT_EQ(*s.checks.collisions_max, 0);
  EXPECT_DOUBLE_EQ(*s.checks.time_to_goal_max_s, 60.0);
  EXPECT_EQ(*s.checks.recoveries_max, 2);
  EXPECT_DOUBLE_EQ(*s.checks.blocked_time_max_s, 5.0);
}

TEST(ScenarioNavigation, ErrorsNameTheKeyAndLine) {
  EXPECT_THAT(error_of(std::string(kClosedLoop) + "  local_costmap:\n    inflation_layer: {inflation_radius: 0.1}\n"),
              HasSubstr("x.yaml:10: navigation.local_costmap.inflation_layer.inflation_radius"));
  EXPECT_THAT(error_of(std::string(kClosedLoop) + "  local_costmap: {width: -3}\n"),
              HasSubstr("navigation.local_costmap.width"));
  EXPECT_THAT(error_of(std::string(kClosedLoop) + "  behaviors: {backup_speed: 0}\n"),
              HasSubstr("navigation.behaviors.backup_speed"));
  EXPECT_THAT(error_of(std::string(kClosedLoop) + "  controller_frequency: .nan\n"),
              HasSubstr("navigation.controller_frequency"));
  EXPECT_THAT(error_of(std::string(kClosedLoop) + "  local_costmap: {widht: 3}\n"), HasSubstr("width"));
  EXPECT_THAT(error_of("name: c\nworld: w.xml\nrobot: {start: [0, 0, 0]}\nnavigation: {mode: closed_loop}\n"),
              HasSubstr("navigation.goal"));
  EXPECT_THAT(error_of("name: c\nworld: w.xml\nrobot: {start: [0, 0, 0]}\nnavigation: {mode: driving}\n"),
              HasSubstr("path or closed_loop"));
  EXPECT_THAT(error_of(std::string(kMinimal) + "checks: {navigation_success: true}\n"),
              HasSubstr("needs navigation.mode closed_loop"));
  EXPECT_THAT(error_of(std::string(kClosedLoop) + "stop_at_path_end: true\n"), HasSubstr("stop_at_path_end"));
  EXPECT_THAT(
      error_of("name: c\nworld: w.xml\nrobot: {start: [0, 0, 0]}\nnavigation: {mode: closed_loop, goal: [1, 2]}\n"),
      HasSubstr("[x_m, y_m, yaw_deg]"));
}

TEST(ScenarioNavigation, AGoalOnANav2MapMustBeOnAFreeCell) {
  const std::string file = std::string(STVL_SOURCE_DIR) + "/scenarios/office_floor_map.yaml";
  const Scenario s = load_scenario(file, {"navigation.mode=closed_loop"});  // the planned path's end
  EXPECT_EQ(s.navigation.mode, navigation::NavigationMode::kClosedLoop);
  EXPECT_TRUE(s.pipeline.path.waypoints_W.empty());
  // The global costmap's StaticLayer reads the map itself: worlds/maps/office_floor.yaml, 200 x 120 at 0.05 m.
  ASSERT_TRUE(s.navigation.static_map.has_value());
  EXPECT_EQ(s.navigation.static_map->width, 200);
  EXPECT_EQ(s.navigation.static_map->height, 120);
  EXPECT_EQ(s.navigation.static_map->origin_m, Eigen::Vector2d(-1.0, -2.0));
  EXPECT_EQ(s.navigation.static_map->data.front(), 100);  // the outer wall's corner cell
  EXPECT_NE(std::count(s.navigation.static_map->data.begin(), s.navigation.static_map->data.end(), -1), 0);
  const std::string error = invalid_argument_of([&] {
    load_scenario(file, {"navigation.mode=closed_loop", "navigation.goal=[100,0,0]"});
  });
  EXPECT_THAT(error, HasSubstr("lies outside the nav2 map"));
  EXPECT_THAT(error, HasSubstr("the nearest free cell is"));
}

}  // namespace
}  // namespace stvl::config

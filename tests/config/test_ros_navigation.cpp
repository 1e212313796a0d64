// nav2's servers from a nav2 parameter file (config/ros_navigation.hpp): the closed loop's keys read, plugins that
// are not modelled reported with what stands in, and scenarios taking the file through navigation.ros_params.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "config/ros_navigation.hpp"
#include "config/scenario.hpp"
#include "tests/support/invalid_argument.hpp"

namespace stvl::config {
namespace {

using ::testing::HasSubstr;

std::string write_file(const std::string& name, const std::string& text) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("stvl_ros_navigation_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream((dir / name).string()) << text;
  return (dir / name).string();
}

// nav2_bringup's layout, RPP and NavFn as a robot would write them.
const char* const kParams = R"(controller_server:
  ros__parameters:
    controller_frequency: 10.0
    failure_tolerance: 0.5
    progress_checker_plugins: ["progress_checker"]
    goal_checker_plugins: ["general_goal_checker"]
    controller_plugins: ["FollowPath"]
    progress_checker:
      plugin: "nav2_controller::SimpleProgressChecker"
      required_movement_radius: 0.3
      movement_time_allowance: 8.0
    general_goal_checker:
      plugin: "nav2_controller::SimpleGoalChecker"
      xy_goal_tolerance: 0.15
      yaw_goal_tolerance: 0.5
      stateful: False
    FollowPath:
      plugin: "nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController"
      desired_linear_vel: 0.7
      lookahead_dist: 0.8
      use_rotate_to_heading: false
planner_server:
  ros__parameters:
    planner_plugins: ["GridBased"]
    GridBased:
      plugin: "nav2_navfn_planner/NavfnPlanner"
      tolerance: 0.25
      use_astar: true
local_costmap:
  local_costmap:
    ros__parameters:
      update_frequency: 10.0
      width: 4
      height: 4
      resolution: 0.05
      footprint: "[[0.3, 0.25], [-0.3, 0.25], [-0.3, -0.25], [0.3, -0.25]]"
      plugins: ["voxel_layer", "inflation_layer"]
      inflation_layer:
        plugin: "nav2_costmap_2d::InflationLayer"
        cost_scaling_factor: 4.0
        inflation_radius: 0.6
global_costmap:
  global_costmap:
    ros__parameters:
      resolution: 0.1
      track_unknown_space: false
      plugins: ["static_layer", "inflation_layer"]
      inflation_layer:
        plugin: "nav2_costmap_2d::InflationLayer"
        inflation_radius: 0.9
behavior_server:
  ros__parameters:
    max_rotational_vel: 0.8
    simulate_ahead_time: 1.5
)";

TEST(RosNavigation, ServersKeysAreRead) {
  navigation::NavigationConfig c;
  const auto findings = read_ros_navigation(write_file("nav2.yaml", kParams), c);
  EXPECT_TRUE(findings.empty()) << (findings.empty() ? "" : format_finding(findings.front()));
  EXPECT_DOUBLE_EQ(c.controller_frequency_hz, 10.0);
  EXPECT_DOUBLE_EQ(c.failure_tolerance_s, 0.5);
  EXPECT_DOUBLE_EQ(c.progress_checker.required_movement_radius, 0.3);
  EXPECT_DOUBLE_EQ(c.goal_checker.xy_goal_tolerance, 0.15);
  EXPECT_FALSE(c.goal_checker.stateful);
  EXPECT_DOUBLE_EQ(c.controller.desired_linear_vel, 0.7);
  EXPECT_DOUBLE_EQ(c.controller.lookahead_dist, 0.8);
  EXPECT_FALSE(c.controller.use_rotate_to_heading);
  EXPECT_DOUBLE_EQ(c.planner.tolerance_m, 0.25);  // the old pluginlib name (nav2_navfn_planner/NavfnPlanner) too
  EXPECT_TRUE(c.planner.use_astar);
  EXPECT_DOUBLE_EQ(c.local_costmap.update_frequency_hz, 10.0);
  EXPECT_DOUBLE_EQ(c.local_costmap.width_m, 4.0);
  EXPECT_DOUBLE_EQ(c.local_costmap.inflation.cost_scaling_factor, 4.0);
  EXPECT_DOUBLE_EQ(c.local_costmap.inflation.inflation_radius_m, 0.6);
  ASSERT_EQ(c.footprint_m.size(), 4u);  // the local costmap's footprint
  EXPECT_DOUBLE_EQ(c.footprint_m[0].x(), 0.3);
  EXPECT_DOUBLE_EQ(c.global_costmap.resolution_m, 0.1);
  EXPECT_FALSE(c.global_costmap.track_unknown_space);
  EXPECT_DOUBLE_EQ(c.global_costmap.inflation.inflation_radius_m, 0.9);
  EXPECT_DOUBLE_EQ(c.behaviors.max_rotational_vel, 0.8);
  EXPECT_DOUBLE_EQ(c.behaviors.simulate_ahead_time_s, 1.5);
  EXPECT_NO_THROW(c.validate());
}

TEST(RosNavigation, PluginsNotModelledAreFindingsNamingWhatStandsIn) {
  std::string text = kParams;
  text.replace(text.find("nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController"),
               std::string("nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController").size(),
               "nav2_mppi_controller::MPPIController");
  text.replace(text.find("nav2_navfn_planner/NavfnPlanner"), std::string("nav2_navfn_planner/NavfnPlanner").size(),
               "nav2_smac_planner::SmacPlanner2D");
  text += "bt_navigator:\n  ros__parameters:\n    default_nav_to_pose_bt_xml: /my/tree.xml\n";
  navigation::NavigationConfig c;
  const auto findings = read_ros_navigation(write_file("mppi.yaml", text), c);
  ASSERT_EQ(findings.size(), 3u);
  EXPECT_THAT(format_finding(findings[0]), HasSubstr("FollowPath.plugin"));
  EXPECT_THAT(format_finding(findings[0]), HasSubstr("MPPIController"));
  EXPECT_THAT(format_finding(findings[0]), HasSubstr("Regulated Pure Pursuit"));
  EXPECT_THAT(format_finding(findings[1]), HasSubstr("SmacPlanner2D"));
  EXPECT_THAT(format_finding(findings[1]), HasSubstr("NavFn"));
  EXPECT_THAT(format_finding(findings[2]), HasSubstr("/my/tree.xml"));
  EXPECT_THAT(format_finding(findings[2]), HasSubstr("navigate_to_pose_w_replanning_and_recovery.xml"));
  EXPECT_GT(findings[0].line, 0);
  EXPECT_DOUBLE_EQ(c.controller.desired_linear_vel, 0.5);  // MPPI's keys are not RPP's: RPP's defaults stand in
  EXPECT_DOUBLE_EQ(c.planner.tolerance_m, 0.5);
}

TEST(RosNavigation, BadValuesAndFilesWithoutServersAreErrors) {
  navigation::NavigationConfig c;
  std::string bad = kParams;
  bad.replace(bad.find("controller_frequency: 10.0"), std::string("controller_frequency: 10.0").size(),
              "controller_frequency: fast");
  EXPECT_THAT(test::invalid_argument_of([&] { read_ros_navigation(write_file("bad.yaml", bad), c); }),
              HasSubstr("controller_server.ros__parameters.controller_frequency"));
  EXPECT_THAT(test::invalid_argument_of(
                  [&] { read_ros_navigation(write_file("none.yaml", "stvl_layer:\n  voxel_size: 0.05\n"), c); }),
              HasSubstr("no nav2 server"));
}

TEST(RosNavigation, AScenarioTakesItsServersFromTheFileAndItsOwnKeysWin) {
  const std::string params = write_file("scenario_nav2.yaml", kParams);
  const Scenario s = parse_scenario(
      "name: c\nworld: w.xml\nrobot: {start: [0, 0, 0]}\nnavigation:\n"
      "  mode: closed_loop\n  goal: [5, 0, 0]\n  ros_params: " +
          params + "\n  controller_frequency: 15\n",
      "x.yaml", "/base");
  EXPECT_EQ(s.navigation_ros_params, params);
  EXPECT_DOUBLE_EQ(s.navigation.controller_frequency_hz, 15.0);  // the scenario's key over the file's 10
  EXPECT_DOUBLE_EQ(s.navigation.controller.desired_linear_vel, 0.7);
  EXPECT_EQ(s.navigation.footprint_m.size(), 4u);
}

}  // namespace
}  // namespace stvl::config

#pragma once
// nav2's servers as a nav2 parameter file (nav2_params.yaml, ROS 2) writes them, read into the closed loop's
// settings (navigation/config.hpp): controller_server (controller_frequency, failure_tolerance, the goal and
// progress checkers, FollowPath), planner_server (GridBased), local_costmap and global_costmap (sizes, resolution,
// update_frequency, track_unknown_space, robot_radius or footprint, footprint_padding, their inflation layer),
// behavior_server and bt_navigator. Plugins the bench does not model (MPPI, DWB, Smac, another tree) are findings
// naming what stands in for them; the run still goes.
#include <string>
#include <vector>

#include "config/ros_lint.hpp"
#include "navigation/config.hpp"

namespace stvl::config {

// Keys present in `path` override `config`'s values; returns the findings (each "what runs instead"). Throws
// std::invalid_argument "file:line: key: message" for malformed YAML or values of the wrong type, and for a file
// with none of nav2's servers.
std::vector<LintFinding> read_ros_navigation(const std::string& path, navigation::NavigationConfig& config);

}  // namespace stvl::config

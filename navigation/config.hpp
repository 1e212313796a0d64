#pragma once
// The closed loop's settings: nav2's keys (nav2_bringup jazzy f4108e5 params/nav2_params.yaml where nav2's own
// defaults leave a choice to the robot: costmap sizes, inflation, failure_tolerance), grouped as nav2's servers are.
// Scenario YAML `navigation:` (config/scenario_navigation.cpp) fills it; every default here is the YAML key's.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "navigation/checkers.hpp"
#include "navigation/inflation.hpp"
#include "navigation/navfn.hpp"
#include "navigation/rpp.hpp"

namespace stvl::navigation {

// How the robot drives: a fixed path (robot.waypoints, the default) or nav2 from the costmap (closed_loop).
enum class NavigationMode { kPath, kClosedLoop };
NavigationMode parse_navigation_mode(const std::string& text);  // "path" | "closed_loop"; throws with the names

// FollowPath's keys as nav2 names them and the RppParams field each sets (max_robot_pose_search_dist aside: optional).
std::vector<std::pair<const char*, double*>> rpp_double_keys(RppParams& p);
std::vector<std::pair<const char*, bool*>> rpp_bool_keys(RppParams& p);

// One costmap of nav2 (Costmap2DROS): its window, clock and inflation layer.
struct CostmapParams {
  double width_m = 3.0, height_m = 3.0;  // width, height (local: the rolling window; global: the map's extent)
  double resolution_m = 0.05;            // resolution
  double update_frequency_hz = 5.0;      // update_frequency
  double publish_frequency_hz = 2.0;     // publish_frequency (the bag's costmap topic)
  bool rolling_window = true;            // rolling_window
  bool track_unknown_space = false;      // track_unknown_space
  // inflation_layer: nav2_bringup's nav2_params.yaml (jazzy) writes inflation_radius 0.70 and cost_scaling_factor
  // 3.0 for both costmaps (nav2's own defaults: 0.55 and 10.0).
  InflationParams inflation{0.70, 3.0, false, false};
};

// nav2_behaviors (behavior_server, jazzy f4108e5) and the default tree's arguments to them.
struct BehaviorParams {
  double cycle_frequency_hz = 10.0;    // behavior_server cycle_frequency
  double simulate_ahead_time_s = 2.0;  // simulate_ahead_time
  double max_rotational_vel = 1.0;     // max_rotational_vel (rad/s)
  double min_rotational_vel = 0.4;     // min_rotational_vel
  double rotational_acc_lim = 3.2;     // rotational_acc_lim (rad/s^2)
  double time_allowance_s = 10.0;      // the Spin and BackUp actions' time_allowance
  double spin_dist_rad = 1.57;         // the tree's <Spin spin_dist>
  double backup_dist_m = 0.30;         // <BackUp backup_dist>
  double backup_speed_mps = 0.15;      // <BackUp backup_speed>
  double wait_duration_s = 5.0;        // <Wait wait_duration>
};

// A nav2 map as map_server publishes it (nav_msgs/OccupancyGrid): -1 unknown, 0 free .. 100 occupied, row 0 at
// origin_m's y; for the global costmap's StaticLayer (static_layer_costmap in costmaps.hpp).
struct OccupancyMap {
  int width = 0, height = 0;
  double resolution_m = 0.05;
  Eigen::Vector2d origin_m = Eigen::Vector2d::Zero();
  std::vector<std::int8_t> data;  // data[row * width + col]
};

struct NavigationConfig {
  NavigationMode mode = NavigationMode::kPath;  // navigation.mode
  Pose2 goal;                                   // navigation.goal [x, y, yaw] (world = map frame)
  double robot_radius_m = 0.22;                 // robot_radius (the costmaps'); footprint_m wins when given
  std::vector<Eigen::Vector2d> footprint_m;     // footprint, base_link frame
  double footprint_padding_m = 0.01;            // footprint_padding (Costmap2DROS)
  double controller_frequency_hz = 20.0;        // controller_server controller_frequency
  double failure_tolerance_s = 0.3;             // controller_server failure_tolerance
  // controller_server and planner_server costmap_update_timeout: how long each waits for a current costmap
  // (the 3D layer's sources within expected_update_rate) before ControllerTimedOut / PlannerTimedOut.
  double controller_costmap_timeout_s = 0.3;
  double planner_costmap_timeout_s = 1.0;
  double replan_frequency_hz = 1.0;  // the tree's <RateController hz> around ComputePathToPose
  int number_of_retries = 6;         // the tree's NavigateRecovery number_of_retries
  CostmapParams local_costmap;       // local_costmap (rolling, in odom)
  CostmapParams global_costmap{0.0, 0.0, 0.05, 1.0, 1.0, false, true, {0.70, 3.0, false, false}};  // global_costmap
  NavfnParams planner;                     // planner_server GridBased
  RppParams controller;                    // controller_server FollowPath
  GoalCheckerParams goal_checker;          // general_goal_checker
  ProgressCheckerParams progress_checker;  // progress_checker
  BehaviorParams behaviors;                // behavior_server
  // The bodies a mapping run would have left in the static map: names starting with one of these.
  std::vector<std::string> static_bodies{"wall", "door"};
  // A scenario's nav2_map: the global costmap's StaticLayer reads it (its size, resolution and unknown cells)
  // instead of the bodies above.
  std::optional<OccupancyMap> static_map;

  // Throws std::invalid_argument naming the key (navigation.local_costmap.inflation_radius, ...) for values out
  // of range, an inflation radius below the inscribed radius included.
  void validate() const;
  // The inscribed radius nav2 computes from the footprint (its nearest edge) or robot_radius.
  double inscribed_radius_m() const;
  // The footprint the costmaps use: footprint_m, or robot_radius as makeFootprintFromRadius's 16 points, padded by
  // footprint_padding (padFootprint: each coordinate moved away from 0 by the padding).
  std::vector<Eigen::Vector2d> footprint_polygon_m() const;
};

}  // namespace stvl::navigation

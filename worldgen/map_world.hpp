#pragma once
// A world from a nav2 map: the floor, the occupied cells extruded to walls and merged into few boxes (rotated
// with the map's origin yaw), the robot included from robot.xml; the robot's path planned through the free cells;
// the scenario beside it.
#include <optional>
#include <string>

#include <Eigen/Core>

#include "worldgen/mjcf_writer.hpp"
#include "worldgen/nav2_map.hpp"
#include "worldgen/occupancy.hpp"
#include "worldgen/planner.hpp"

namespace stvl::worldgen {

// Added to the robot's footprint radius for planning: the path follower's tracking error and the slack of
// corners it rounds stay inside it.
inline constexpr double kPathMarginM = 0.05;

struct MapWorld {
  std::string map_yaml;  // where it came from
  Nav2Map map;
  OccupancyGrid grid;
  WorldSpec spec;
  std::size_t wall_boxes = 0;
};

// Loads the map and builds its world; wall_height_m in (0, 10]. Throws std::invalid_argument naming the file and
// the fix (nav2_map.hpp), or the wall height.
MapWorld build_map_world(const std::string& map_yaml, double wall_height_m);

// The robot's drivable cells on the map: free cells at least robot_radius_m + kPathMarginM from walls.
DriveGrid map_drive_grid(const MapWorld& world, double robot_radius_m);

// The scenario text for the world written as world_file beside it: the planned path and the defaults of
// scenario_writer.hpp.
std::string map_scenario_yaml(const MapWorld& world, const PlannedPath& path, const std::string& name,
                              const std::string& world_file);

}  // namespace stvl::worldgen

#pragma once
// A generated office: make_layout's corridors and rooms, furniture in the rooms and along the corridors, a
// wall-mounted fire extinguisher, people standing and walking (mocap bodies: a walk to a point of a room and back
// as the robot passes its door, or one brief crossing of the corridor ahead of the robot, over before the robot
// can be within 4.8 m of it; walks are bounded, a moving body costs the evaluation every frame), and the robot's
// path from a room at the far end of the main corridor, out of its open door, along the corridor and up the
// branch to its end, planned with the planner of planner.hpp. One seed gives one world, byte for byte.
#include <cstdint>
#include <string>
#include <vector>

#include "worldgen/mjcf_writer.hpp"
#include "worldgen/office_layout.hpp"
#include "worldgen/planner.hpp"
#include "worldgen/scenario_writer.hpp"

namespace stvl::worldgen {

struct OfficeOptions {
  std::uint64_t seed = 1;
  double width_m = 20, height_m = 12;  // the building; 12..60 by 8..40 m
  int people = 3;                      // 0..20
  double wall_height_m = 2.5;
  double speed_mps = 0.6;
};

struct OfficeWorld {
  OfficeLayout layout;
  WorldSpec spec;
  OccupancyGrid grid;  // every footprint the robot's path was planned around (walking people's lanes included)
  DriveGrid drive;     // its drivable cells
  PlannedPath path;
  std::vector<MovingBodySpec> walks;
  std::string summary;  // one line: rooms, doors, furniture, people, path
};

// Throws std::invalid_argument for options out of range, or when no path fits (it names the seed).
OfficeWorld generate_office(const OfficeOptions& options, double robot_radius_m);

// The scenario text for the generated world written as world_file beside it.
std::string office_scenario_yaml(const OfficeWorld& world, const OfficeOptions& options, const std::string& name,
                                 const std::string& world_file);

}  // namespace stvl::worldgen

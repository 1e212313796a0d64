#pragma once
// The scenario YAML beside a generated world: the planned path, the walking people's mocap tracks, the camera,
// filter and map of scenarios/office_corridor.yaml, a duration from the path, and checks whose comments say
// what they guard.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace stvl::worldgen {

struct Keyframe {
  double t_s = 0;
  Eigen::Vector3d position_W = Eigen::Vector3d::Zero();
  double yaw_deg = 0;
};

// A mocap body's scripted walk (scenario key moving_bodies).
struct MovingBodySpec {
  std::string body;
  std::string comment;
  std::vector<Keyframe> keyframes;
  std::optional<double> repeat_s;
};

struct ScenarioSpec {
  std::string name;
  std::string description;  // comment lines at the top (without '#')
  std::string world_file = "world.xml";
  std::uint64_t seed = 1;
  Eigen::Vector3d start = Eigen::Vector3d::Zero();  // x_m, y_m, yaw_deg
  std::vector<Eigen::Vector2d> waypoints_W;
  double speed_mps = 0.6;
  std::vector<MovingBodySpec> moving_bodies;
};

// Simulated time the path follower needs at speed_mps (sim/path_follower.hpp): the length at cruise speed, a stop
// and a turn in place at every corner sharper than 0.5 rad (the angle at 0.8 rad/s and 2 s to brake and start
// again), the first alignment, then 30 % and 10 s spare. Scenario runs stop at the path's end, so spare time costs
// nothing when the robot arrives.
double drive_duration_s(const std::vector<Eigen::Vector2d>& waypoints_W, double speed_mps, double start_yaw_rad);

// The scenario as YAML text with comments (keys as scenarios/README.md documents them). Throws
// std::invalid_argument when the drive needs more than 3600 s (a scenario's limit).
std::string write_scenario_yaml(const ScenarioSpec& spec);

}  // namespace stvl::worldgen

#pragma once
// The base moved exactly along a path, without wheel physics (robot.drive: kinematic): from the start pose it
// turns in place toward the first waypoint and drives there, then at every waypoint turns in place to the next
// leg's heading and drives the leg straight; speeds ramp up and down under the path follower's limits. The pose
// is a function of time, so it lies on the polyline (and on the start's leg to it) up to rounding. A looping path
// goes round without end, a lap at each return to the first waypoint (as PathFollower counts them).
#include <string>
#include <vector>

#include "sim/path_follower.hpp"

namespace stvl::sim {

// How the robot's base moves: wheels on the floor under the physics, or placed along the path each step.
enum class DriveMode { kPhysics, kKinematic, kAuto };
// "physics", "kinematic", "auto"; parse throws std::invalid_argument naming the choices.
DriveMode parse_drive_mode(const std::string& text);
std::string to_string(DriveMode mode);

class KinematicDrive {
 public:
  // The ramps: decel_mps2 (speeding up and slowing down), max_angular_speed_radps, angular_decel_radps2.
  explicit KinematicDrive(PathFollowerConfig limits = {});

  // The trajectory from `start` at time t0_s through the path's waypoints at its cruise speed. Throws
  // std::invalid_argument as PathFollower::set_path does, and for a non-finite start or time.
  void set_path(const Path& path, const Pose2D& start, double t0_s);
  bool has_path() const { return !segments_.empty(); }

  struct State {
    Pose2D pose;
    Twist2D twist;  // body frame: v along the heading, omega about z
  };
  // The pose and twist at time t_s (held at the start before t0_s, at the end after a path that ends).
  State at(double t_s) const;
  // Whether a path that ends has been driven to its end by t_s (never for a looping path).
  bool finished(double t_s) const;
  // Returns to the first waypoint of a looping path by t_s (0 for other paths).
  int laps_completed(double t_s) const;

 private:
  struct Segment {
    Pose2D from;
    double length = 0;  // m along the heading (a leg) or rad (a turn, signed)
    bool turn = false;
    double duration_s = 0;
  };
  void add_turn(Pose2D& at, double heading_rad, std::vector<Segment>& out) const;
  void add_leg(Pose2D& at, const Eigen::Vector2d& to, std::vector<Segment>& out) const;
  State state_in(const Segment& s, double t_s) const;

  PathFollowerConfig limits_;
  double cruise_mps_ = 0.5;
  double t0_s_ = 0;
  std::vector<Segment> segments_;  // the approach, then one lap (or the whole path)
  std::size_t lap_begin_ = 0;      // first segment of the lap that repeats (looping paths)
  bool loop_ = false;
  double approach_s_ = 0, lap_s_ = 0, last_turn_s_ = 0;
};

}  // namespace stvl::sim

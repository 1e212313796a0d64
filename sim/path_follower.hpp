#pragma once
// Pure pursuit along a 2D polyline. Vertices where the path turns by more than corner_angle_rad
// split it into legs: the robot decelerates to a stop on each such corner, turns in place toward
// the next leg and goes on, so sharp corners are not cut. Output is a body twist (v, omega);
// DiffDriveRobot turns it into wheel speeds under its acceleration limits. A looping path goes on from the
// last waypoint back to the first and around again without end (a patrol): each return to the first
// waypoint ends a lap, where the robot turns in place toward the first leg.
#include <cstddef>
#include <vector>

#include <Eigen/Core>

namespace stvl::sim {

// A planar pose in the world frame: position and heading (yaw about z, counter-clockwise from +x).
struct Pose2D {
  double x_m = 0.0;
  double y_m = 0.0;
  double yaw_rad = 0.0;
};

struct Path {
  std::vector<Eigen::Vector2d> waypoints_W;
  double cruise_speed_mps = 0.5;
  bool loop = false;     // after the last waypoint, back to the first and around again (never finished)
  bool reverse = false;  // driven backwards, the rear leading (YAML robot.reverse): negative linear speeds
};

struct Twist2D {
  double v_mps = 0.0;
  double omega_radps = 0.0;
};

struct PathFollowerConfig {
  double lookahead_m = 0.4;
  double goal_tolerance_m = 0.03;
  double corner_angle_rad = 0.5;
  double align_angle_rad = 0.8;  // rotate in place first when the target is further off
  double heading_tolerance_rad = 0.03;
  double max_angular_speed_radps = 1.2;
  double decel_mps2 = 0.5;            // keep below DiffDriveConfig::max_linear_accel_mps2
  double angular_decel_radps2 = 1.5;  // keep below DiffDriveConfig::max_angular_accel_radps2
  double min_speed_mps = 0.04;
  double max_cruise_speed_mps = 1.2;
};

class PathFollower {
 public:
  explicit PathFollower(PathFollowerConfig config = {});

  // Throws std::invalid_argument on fewer than 2 waypoints, non-finite or repeated consecutive
  // points, or a cruise speed outside (0, max_cruise_speed_mps]. A looping path may end on its first
  // waypoint (a closed polygon) or not (the closing leg is added); it needs 2 distinct waypoints.
  void set_path(const Path& path);
  // Twist for the robot at p_W with heading yaw_rad. Zero once finished.
  Twist2D update(const Eigen::Vector2d& p_W, double yaw_rad);
  bool finished() const { return finished_; }
  bool has_path() const { return !path_.waypoints_W.empty(); }
  // Returns to the first waypoint of a looping path so far (0 for other paths).
  int laps_completed() const { return laps_; }
  // Distance from p_W to the whole polyline.
  double cross_track_error_m(const Eigen::Vector2d& p_W) const;
  // The path as followed: a looping one ends with its first waypoint again.
  const Path& path() const { return path_; }

 private:
  // update() for a robot heading yaw_rad forward (reverse: the rear's heading, the speed negated by update()).
  Twist2D update_forward(const Eigen::Vector2d& p_W, double yaw_rad);
  enum class Mode { align, track, turn_at_corner };
  Eigen::Vector2d point_at(double s) const;  // arc length along the whole path
  double project(const Eigen::Vector2d& p_W, double s_from, double s_to) const;
  double heading_at(double s) const;
  Twist2D rotate_toward(double heading_rad, double yaw_rad);

  PathFollowerConfig config_;
  Path path_;
  std::vector<double> s_vertex_;  // cumulative arc length at each waypoint
  std::vector<double> s_corner_;  // arc length of leg ends (sharp corners and the path end)
  std::size_t leg_ = 0;
  double s_ = 0.0;
  Mode mode_ = Mode::align;
  bool finished_ = false;
  int laps_ = 0;
};

}  // namespace stvl::sim

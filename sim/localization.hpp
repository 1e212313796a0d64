#pragma once
// Localization as a robot has it (issue 43): a localizer (AMCL-like) publishes map -> odom at rate_hz; each
// correction carries the estimate of the robot's pose then, off the truth by a normal error per correction
// (noise_xy_m on each axis of the map, noise_yaw_rad on the heading) plus the offset of the last scripted jump before
// it (a relocalization that goes wrong, or one that puts it right). Between corrections tf holds the last one, so
// the robot's pose in map is that correction composed with odometry since: the odometry's own drift shows up there.
// Counter-based and seeded: correction k has the same error in every run.
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

namespace stvl::sim {

// A scripted jump: from at_s on (until the next jump) the estimate is off the truth by (x_m, y_m) in map and yaw_rad.
struct LocalizationJump {
  double at_s = 0, x_m = 0, y_m = 0, yaw_rad = 0;
};

// YAML localization; absent: localization is perfect (map -> odom exactly cancels odometry's drift).
struct LocalizationConfig {
  bool enabled = false;                 // the block is present
  double rate_hz = 10.0;                // rate_hz: map -> odom corrections per second (correction k at k / rate_hz)
  double noise_xy_m = 0.0;              // noise_xy_m: standard deviation of the estimate's x and y error per correction
  double noise_yaw_rad = 0.0;           // noise_yaw_rad: standard deviation of its heading error
  std::vector<LocalizationJump> jumps;  // jumps: [{at_s, x_m, y_m, yaw_rad}, ...], in time order
  // global_frame: the frame of the run's layer, as nav2's costmap global_frame: map (false; the global costmap's:
  // readings placed with the localizer's pose) or odom (true; the local costmap's: odometry alone, no corrections).
  bool layer_in_odom = false;
  std::uint64_t seed = 1;  // the scenario's seed (the draws of correction k derive from it and k)
  // Throws std::invalid_argument naming the key for a rate <= 0 or above 1000 Hz, negative or NaN noise, a jump not
  // finite, out of time order or at or after duration_s (an offset larger than the run), or of 10 m or pi and more.
  void validate(double duration_s) const;
};

// The estimate's error at one correction: the estimated pose is the true one moved by (x_m, y_m) in map, turned by
// yaw_rad about the robot.
struct PoseError2 {
  double x_m = 0, y_m = 0, yaw_rad = 0;
};

// One published correction: its time, map -> odom as published, and the estimate's error then.
struct LocalizationCorrection {
  double time_s = 0;
  Eigen::Isometry3d T_map_odom = Eigen::Isometry3d::Identity();
  PoseError2 error;
};

// The index of the correction in force at time_s (the last one published at or before it; 0 before the first).
std::uint64_t correction_index(const LocalizationConfig& config, double time_s);
// Correction k's error: its noise drawn from (seed, k), plus the offset of the last jump at or before k / rate_hz.
PoseError2 localization_error(const LocalizationConfig& config, std::uint64_t seed, std::uint64_t k);

}  // namespace stvl::sim

#pragma once
// One world, its robot, a path follower, wheel odometry and mocap scripts, stepped together.
//   stvl::sim::Simulator sim(stvl::sim::World::from_file("worlds/office_corridor.xml"));
//   sim.set_path({{{0, 0}, {5, 0}}, 0.6});
//   while (!sim.path_finished() && sim.time_s() < 30) sim.step();
#include <functional>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "sim/diff_drive.hpp"
#include "sim/kinematic_drive.hpp"
#include "sim/localization.hpp"
#include "sim/mocap_script.hpp"
#include "sim/odometry.hpp"
#include "sim/path_follower.hpp"
#include "sim/world.hpp"

namespace stvl::sim {

struct SimulatorConfig {
  DiffDriveConfig robot;
  PathFollowerConfig follower;
  OdometryConfig odometry;
  LocalizationConfig localization;  // map -> odom as a localizer publishes it (disabled: exact)
  CameraMount camera_mount;
  double control_period_s = 0.02;  // path follower rate; wheel commands are rate-limited every step
  // kPhysics: the path follower's wheel commands through the physics. kKinematic: the base placed along the path
  // every step (KinematicDrive), the robot's geoms touching nothing. kAuto is resolved before (sim/urdf_robot.hpp).
  DriveMode drive = DriveMode::kPhysics;
};

class Simulator {
 public:
  // Throws std::invalid_argument if the world lacks the robot or the config is out of range (drive kAuto too).
  explicit Simulator(World world, SimulatorConfig config = {});
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  // Places the robot at rest and restarts odometry (T_odom_base = identity here).
  void set_start_pose(const Pose2D& pose_W);
  void set_path(const Path& path);
  bool path_finished() const { return kinematic_ ? kinematic_->finished(time_s()) : follower_.finished(); }
  // Returns to the first waypoint of a looping path so far (0 for other paths).
  int laps_completed() const { return kinematic_ ? kinematic_->laps_completed(time_s()) : follower_.laps_completed(); }
  void set_mocap_tracks(std::vector<MocapTrack> tracks);
  // Closed loop (navigation/): `controller` is called every period_s of simulated time (its first call at the next
  // step) with the time and returns the body twist to drive, in place of the path follower (physics: through the
  // wheels' acceleration limits; kinematic: the base moved by the twist). Throws std::invalid_argument for a
  // period that is not a positive number or a robot with a path.
  using TwistController = std::function<Twist2D(double time_s)>;
  void set_controller(TwistController controller, double period_s);
  // The twist the controller asked for last (zero without one).
  const Twist2D& commanded_twist() const { return commanded_; }

  // One physics step: controller (every control_period_s), wheel commands, physics, mocap
  // script at the new time, kinematics, odometry, then the localizer's corrections due at the new time. A kinematic
  // drive places the base after the physics instead.
  void step();
  // Steps until time_s() >= t_s.
  void run_until(double t_s);

  double time_s() const { return world_.time_s(); }
  World& world() { return world_; }
  const World& world() const { return world_; }
  DiffDriveRobot& robot() { return robot_; }
  const DiffDriveRobot& robot() const { return robot_; }
  const PathFollower& follower() const { return follower_; }
  const WheelOdometry& odometry() const { return odometry_; }

  Eigen::Isometry3d T_world_base() const { return robot_.T_world_base(); }
  Eigen::Isometry3d T_odom_base() const { return odometry_.T_odom_base(); }
  // map -> odom as tf has it now: with localization the last correction the localizer published, else exact (the
  // truth composed with odometry: the start pose plus the drift).
  Eigen::Isometry3d T_map_odom() const;
  // With localization: the correction in force at time_s (at most now), and every one published so far.
  Eigen::Isometry3d T_map_odom_at(double time_s) const;
  const std::vector<LocalizationCorrection>& corrections() const { return corrections_; }
  // The robot in map as tf has it now: T_map_odom() composed with odometry (the localizer's estimate).
  Eigen::Isometry3d T_map_base() const { return T_map_odom() * T_odom_base(); }
  Eigen::Isometry3d T_world_camera() const { return robot_.T_world_camera(); }
  // The optical frame of a camera on `mount` (the site above follows config.camera_mount only).
  Eigen::Isometry3d T_world_camera(const CameraMount& mount) const {
    return T_world_base() * T_base_camera_link(mount) * DiffDriveRobot::T_camera_link_optical();
  }

 private:
  void advance();  // step() but the localizer
  void kinematic_step();
  void publish_corrections();  // the localizer's corrections due by now, from the truth and odometry now

  World world_;
  SimulatorConfig config_;
  DiffDriveRobot robot_;
  PathFollower follower_;
  WheelOdometry odometry_;
  MocapScript mocap_;
  std::optional<KinematicDrive> kinematic_;  // with DriveMode::kKinematic
  Pose2D hold_;                              // where a kinematic robot without a path stays
  TwistController controller_;
  Twist2D commanded_;
  long steps_per_controller_ = 1;
  int steps_per_control_ = 10;
  long step_count_ = 0;
  std::vector<LocalizationCorrection> corrections_;
};

}  // namespace stvl::sim

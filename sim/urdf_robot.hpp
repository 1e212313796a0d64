#pragma once
// The user's robot from a plain URDF, standing in for worlds/robot.xml (scenario key robot.urdf). The route into
// MuJoCo 2.2.2: the URDF is read here (robot_description/urdf_model.hpp) and written as an MJCF robot.xml
// (robot_description/urdf_mjcf.hpp); a world is then loaded through MuJoCo's virtual file system with that text as the
// robot.xml its <include file="robot.xml"/> names. On top of the URDF: the freejoint on the root link, the
// diff-drive's wheel joints (found or named) with velocity actuators, the rest height, the footprint from the
// collision shapes, and the drive (physics, or kinematic where the URDF's inertias make wheel physics unusable).
//   const UrdfRobot robot = build_urdf_robot({"worlds/urdf/example_bot/example_bot.urdf", {"worlds/urdf"}});
//   Simulator sim(load_world_with_robot("worlds/office_corridor.xml", robot), {robot.diff_drive_config()});
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "robot_description/urdf_model.hpp"
#include "sim/diff_drive.hpp"
#include "sim/kinematic_drive.hpp"
#include "sim/world.hpp"

namespace stvl::sim {

// robot.wheels: the wheel joints named instead of found; a radius or separation of 0 comes from the URDF.
struct UrdfWheelsConfig {
  std::string left_joint, right_joint;  // both or neither
  double radius_m = 0.0;
  double separation_m = 0.0;
};

struct UrdfRobotConfig {
  std::string urdf;                       // the URDF file
  std::vector<std::string> package_path;  // folders package://NAME resolves in (robot_description/package_path.hpp)
  UrdfWheelsConfig wheels;
  DriveMode drive = DriveMode::kAuto;
  double probe_speed_mps = 0.5;  // auto: the physics probe's cruise speed (the scenario's speed_mps)
};

struct UrdfWheels {
  std::string left_joint, right_joint;
  double radius_m = 0.0;
  double track_width_m = 0.0;
  bool named = false;  // robot.wheels named them; else found
};

// A URDF robot ready to stand in for robot.xml.
struct UrdfRobot {
  UrdfRobotConfig config;
  robot_description::UrdfModel urdf;
  UrdfWheels wheels;
  std::string mjcf;          // the robot.xml it stands in for
  double rest_height_m = 0;  // the root link's origin above the floor at rest
  double mass_kg = 0;        // the URDF's usable inertials
  // The convex hull of every collision shape projected on the floor, in the root link's frame (counter-clockwise).
  std::vector<Eigen::Vector2d> footprint_B;
  DriveMode drive = DriveMode::kPhysics;  // auto resolved
  std::string drive_reason;               // why, one line
  std::vector<std::string> notices;       // the URDF's (a visual DAE skipped) and the conversion's (joints held)

  // The diff-drive on this robot: the root link as base body, the wheel joints, their radius and track.
  DiffDriveConfig diff_drive_config() const;
};

// Reads the URDF and builds the robot; drive auto drives a short path on a bare floor with the physics first
// (the probe) unless the root or a wheel has no usable inertial. Throws std::invalid_argument "FILE...: what;
// fix" for the URDF's errors (parse_urdf), wheels neither found nor named (naming the candidates), a named
// joint that is no wheel, and a robot MuJoCo cannot compile (its message).
UrdfRobot build_urdf_robot(const UrdfRobotConfig& config);

// The world at world_path with robot.mjcf in place of its <include file="robot.xml"/>. Throws
// std::invalid_argument when the world has no such include, std::runtime_error with MuJoCo's message.
World load_world_with_robot(const std::string& world_path, const UrdfRobot& robot);

// Whether a link name follows REP-103's optical frame naming ("..._optical_frame": z forward, x right, y down).
bool is_optical_frame(const std::string& link);
// The mount of a camera at URDF link `frame` (camera_link on the root link): an optical frame is the camera's
// optical frame, any other link its camera_link (x forward, y left, z up). Throws std::invalid_argument listing
// the links, nearest name first, when there is no such link.
CameraMount camera_mount_at(const robot_description::UrdfModel& urdf, const std::string& frame);

}  // namespace stvl::sim

#pragma once
// A parsed URDF written as an MJCF robot in robot.xml's form, to be included by a world in its place: the root
// link a body with a freejoint, every other link a body of its own (fixed joints keep their links, so every link
// stays addressable by name), collision shapes as geoms in the robot's group 2, velocity actuators `left_wheel`
// and `right_wheel` on the driven wheel joints, and robot.xml's camera sites and camera on the root body. The
// text uses quaternions and unit-free attributes only, so the world's <compiler angle> cannot change it.
#include <string>
#include <vector>

#include "robot_description/urdf_model.hpp"

namespace stvl::robot_description {

struct MjcfRobotOptions {
  double root_height_m = 0.0;                       // the root body's z in the world at rest
  std::string left_wheel_joint, right_wheel_joint;  // driven hinges; written with their axes along the root's +y
  double wheel_radius_m = 0.05;                     // sets the actuators' gain, torque and speed ranges
  double timestep_s = 0.002;                        // the worlds' timestep: the wheels' armature keeps kv stable
};

struct MjcfRobot {
  std::string xml;
  // Bodies with a MuJoCo joint (the root, hinges) whose URDF inertial is missing or unusable, each with why
  // ("left_wheel_link: no <inertial>"); they carry a stand-in of 1 g so that MuJoCo compiles them.
  std::vector<std::string> stand_in_inertials;
  // Links whose own URDF inertial is usable (mass > 0, inertia positive definite and physical).
  std::vector<std::string> massive_links;
  // Joints held at their rest position (revolute, prismatic, floating, planar), each "name (type)".
  std::vector<std::string> held_joints;
  double mass_kg = 0.0;  // the usable inertials' sum
};

// Throws std::invalid_argument when a wheel joint named in `options` is no continuous or revolute joint of `urdf`.
MjcfRobot urdf_to_mjcf(const UrdfModel& urdf, const MjcfRobotOptions& options);

}  // namespace stvl::robot_description

#include "sim/urdf_robot.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include <tinyxml2.h>

#include "common/enum_names.hpp"
#include "robot_description/urdf_geometry.hpp"
#include "robot_description/urdf_mjcf.hpp"
#include "sim/simulator.hpp"

namespace stvl::sim {

using robot_description::load_urdf;
using robot_description::MjcfRobot;
using robot_description::MjcfRobotOptions;
using robot_description::robot_extent;
using robot_description::RobotExtent;
using robot_description::urdf_to_mjcf;
using robot_description::UrdfJoint;
using robot_description::UrdfJointType;
using robot_description::UrdfLink;
using robot_description::UrdfModel;
using robot_description::UrdfShape;

namespace {

constexpr double kWheelAxisCos = 0.906;     // a wheel's axis lies within 25 degrees of the base's y
constexpr double kWheelMinOffset_m = 0.01;  // and its origin off the centre line by more than this
constexpr double kRestClearance_m = 0.002;  // the lowest point starts this far above the floor (robot.xml's)
// The probe fails a robot that tilts more than this (the camera's view would swing; robot.xml's robot stays under
// 0.05 rad), leaves the floor by more than this, or strays from its path by more than this.
constexpr double kProbeMaxTilt_rad = 0.1;
constexpr double kProbeMaxLift_m = 0.05;
constexpr double kProbeMaxOffPath_m = 0.15;

std::string fixed(double v, int digits = 3) {
  std::ostringstream text;
  text.setf(std::ios::fixed);
  text.precision(digits);
  text << v;
  return text.str();
}

struct Hinge {
  const UrdfJoint* joint;
  Eigen::Vector3d axis_B, origin_B;
  bool on_base;  // only fixed joints between its parent and the root
  std::string describe() const {
    return joint->name + " (axis [" + fixed(axis_B.x(), 2) + ", " + fixed(axis_B.y(), 2) + ", " + fixed(axis_B.z(), 2) +
           "] in the base, y " + fixed(origin_B.y()) + " m" + (on_base ? "" : ", below another moving joint") + ")";
  }
};

std::vector<Hinge> hinges(const UrdfModel& urdf) {
  std::vector<Hinge> out;
  for (const auto& j : urdf.joints) {
    if (j.type != UrdfJointType::kContinuous && j.type != UrdfJointType::kRevolute) continue;
    const Eigen::Isometry3d T = urdf.T_root_link(j.child);
    bool on_base = true;
    for (const UrdfJoint* up = urdf.parent_joint(j.parent); up; up = urdf.parent_joint(up->parent))
      on_base = on_base && up->type == UrdfJointType::kFixed;
    out.push_back({&j, T.linear() * j.axis, T.translation(), on_base});
  }
  return out;
}

std::string described(const std::vector<Hinge>& list) {
  std::string text;
  for (const auto& h : list) text += (text.empty() ? "" : ", ") + h.describe();
  return text.empty() ? "none (no continuous or revolute joint)" : text;
}

// The wheel's radius from its link's collision: a cylinder along the wheel's axis, else a sphere. Sets the
// contact line's y (the shape's centre) in `y_B`. 0 when there is neither.
double wheel_radius(const UrdfModel& urdf, const Hinge& h, double& y_B) {
  const Eigen::Isometry3d T = urdf.T_root_link(h.joint->child);
  const UrdfLink& link = *urdf.find_link(h.joint->child);
  for (const UrdfShape shape : {UrdfShape::kCylinder, UrdfShape::kSphere})
    for (const auto& c : link.collisions) {
      if (c.geometry.shape != shape) continue;
      const Eigen::Isometry3d T_geom = T * c.T_link_geom;
      if (shape == UrdfShape::kCylinder && std::abs(T_geom.linear().col(2).dot(h.axis_B.normalized())) < kWheelAxisCos)
        continue;
      y_B = T_geom.translation().y();
      return c.geometry.radius_m;
    }
  return 0.0;
}

UrdfWheels find_wheels(const UrdfModel& urdf, const UrdfWheelsConfig& named) {
  const std::vector<Hinge> all = hinges(urdf);
  const Hinge* side[2] = {nullptr, nullptr};  // left, right
  const char* side_name[2] = {"left", "right"};
  if (!named.left_joint.empty()) {
    const std::string* names[2] = {&named.left_joint, &named.right_joint};
    for (int s = 0; s < 2; ++s) {
      for (const auto& h : all)
        if (h.joint->name == *names[s]) side[s] = &h;
      if (!side[s])
        throw std::invalid_argument(urdf.file + ": robot.wheels." + side_name[s] +
                                    ": no continuous or revolute joint named '" + *names[s] +
                                    "' (candidates: " + described(all) + ")");
    }
  } else {
    for (int s = 0; s < 2; ++s) {
      std::vector<Hinge> found;
      for (const auto& h : all)
        if (h.on_base && std::abs(h.axis_B.normalized().y()) >= kWheelAxisCos &&
            (s == 0 ? h.origin_B.y() > kWheelMinOffset_m : h.origin_B.y() < -kWheelMinOffset_m))
          found.push_back(h);
      if (found.size() != 1)
        throw std::invalid_argument(
            urdf.file + ": " +
            (found.empty() ? "no " + std::string(side_name[s]) + " wheel joint found"
                           : "several " + std::string(side_name[s]) + " wheel joints: " + described(found)) +
            ". A wheel is a continuous or revolute joint on the base whose axis lies along the base's y, on the " +
            side_name[s] + " (y " + (s == 0 ? "> 0" : "< 0") + "); the joints: " + described(all) +
            ". Name the pair to drive in robot.wheels: {left: JOINT, right: JOINT}");
      for (const auto& h : all)
        if (h.joint == found.front().joint) side[s] = &h;
    }
  }
  UrdfWheels w;
  w.named = !named.left_joint.empty();
  w.left_joint = side[0]->joint->name;
  w.right_joint = side[1]->joint->name;
  double y[2] = {side[0]->origin_B.y(), side[1]->origin_B.y()};
  double radius[2] = {0, 0};
  for (int s = 0; s < 2; ++s) {
    radius[s] = wheel_radius(urdf, *side[s], y[s]);
    if (!(radius[s] > 0) && !(named.radius_m > 0))
      throw std::invalid_argument(
          urdf.file + ": wheel link '" + side[s]->joint->child + "' has no cylinder (along the " +
          "wheel's axis) or sphere collision to take the radius from: give robot.wheels.radius_m");
  }
  w.radius_m = named.radius_m > 0 ? named.radius_m : 0.5 * (radius[0] + radius[1]);
  w.track_width_m = named.separation_m > 0 ? named.separation_m : std::abs(y[0] - y[1]);
  if (!(w.track_width_m > 0))
    throw std::invalid_argument(urdf.file + ": wheels '" + w.left_joint + "' and '" + w.right_joint +
                                "' have no separation along the base's y: give robot.wheels.separation_m");
  return w;
}

constexpr const char* kProbeWorld = R"(<mujoco model="urdf drive probe">
  <compiler autolimits="true"/>
  <option timestep="0.002"/>
  <include file="robot.xml"/>
  <worldbody><geom name="floor" type="plane" size="50 50 0.1"/></worldbody>
</mujoco>)";

World robot_alone(const std::string& mjcf) {
  try {
    return World::from_string(kProbeWorld, "", {{"robot.xml", mjcf}});
  } catch (const std::runtime_error& e) {
    throw std::invalid_argument(std::string("the robot from the URDF does not compile in MuJoCo 2.2.2: ") + e.what());
  }
}

// The drive of a robot whose inertials MuJoCo accepts: a 1.5 m path with a right-angle turn on a bare floor.
struct Probe {
  bool passed = false;
  std::string summary;
};

Probe probe_physics(const UrdfRobot& robot) {
  static int warnings = 0;  // MuJoCo's warnings during the probe are its findings, not output
  warnings = 0;
  void (*previous)(const char*) = mju_user_warning;
  mju_user_warning = [](const char*) { ++warnings; };
  SimulatorConfig config;
  config.robot = robot.diff_drive_config();
  Simulator sim(robot_alone(robot.mjcf), config);
  const double speed = std::clamp(robot.config.probe_speed_mps, 0.1, 1.2);
  sim.set_start_pose({0, 0, 0});
  sim.set_path({{{0, 0}, {1.0, 0}, {1.0, 0.5}}, speed});
  const double limit_s = 2.0 * (1.5 / speed + 2.0 * M_PI / 2.0 / 1.2 + 4.0) + 5.0;
  const double z0 = sim.T_world_base().translation().z();
  double tilt = 0, dz = 0, off_path = 0;
  std::string failure;
  while (!sim.path_finished() && sim.time_s() < limit_s && failure.empty()) {
    sim.step();
    const Eigen::Vector3d p = sim.T_world_base().translation();
    tilt = std::max(tilt, sim.robot().tilt_rad());
    dz = std::max(dz, std::abs(p.z() - z0));
    off_path = std::max(off_path, sim.follower().cross_track_error_m(p.head<2>()));
    if (!p.allFinite() || warnings > 0)
      failure = "the simulation went unstable at t = " + fixed(sim.time_s(), 2) + " s";
    else if (tilt > kProbeMaxTilt_rad)
      failure = "the robot tilted by " + fixed(tilt, 2) + " rad at t = " + fixed(sim.time_s(), 2) + " s (more than " +
                fixed(kProbeMaxTilt_rad, 2) + " rad)";
    else if (dz > kProbeMaxLift_m)
      failure = "the robot left the floor (" + fixed(dz) + " m at t = " + fixed(sim.time_s(), 2) + " s)";
    else if (off_path > kProbeMaxOffPath_m) failure = "the robot strayed " + fixed(off_path, 2) + " m from the path";
  }
  mju_user_warning = previous;
  const Eigen::Vector3d end = sim.T_world_base().translation();
  if (failure.empty() && !sim.path_finished())
    failure = "the robot did not finish the 1.5 m path in " + fixed(limit_s, 0) + " s (it ended at (" +
              fixed(end.x(), 2) + ", " + fixed(end.y(), 2) + ") m, the goal is (1.00, 0.50))";
  if (!failure.empty()) return {false, "the physics probe failed: " + failure};
  return {true, "the physics probe drove a 1.5 m path with a right-angle turn in " + fixed(sim.time_s(), 1) +
                    " s, tilt at most " + fixed(tilt, 3) + " rad, at most " + fixed(off_path, 3) + " m off the path"};
}

// Whether `root` includes a file named robot.xml (any folder), searching its elements.
bool includes_robot_xml(const tinyxml2::XMLElement* e) {
  for (; e; e = e->NextSiblingElement()) {
    const char* file = e->Attribute("file");
    if (std::string(e->Name()) == "include" && file && std::filesystem::path(file).filename() == "robot.xml")
      return true;
    if (includes_robot_xml(e->FirstChildElement())) return true;
  }
  return false;
}

}  // namespace

DiffDriveConfig UrdfRobot::diff_drive_config() const {
  DiffDriveConfig c;
  c.base_body = urdf.root;
  c.left_joint = wheels.left_joint;
  c.right_joint = wheels.right_joint;
  c.wheel_radius_m = wheels.radius_m;
  c.track_width_m = wheels.track_width_m;
  return c;
}

UrdfRobot build_urdf_robot(const UrdfRobotConfig& config) {
  UrdfRobot robot;
  robot.config = config;
  robot.urdf = load_urdf(config.urdf, config.package_path);
  robot.wheels = find_wheels(robot.urdf, config.wheels);
  MjcfRobotOptions options;
  options.left_wheel_joint = robot.wheels.left_joint;
  options.right_wheel_joint = robot.wheels.right_joint;
  options.wheel_radius_m = robot.wheels.radius_m;
  // Written once at the root's origin to measure it, then at its rest height.
  const World measured = robot_alone(urdf_to_mjcf(robot.urdf, options).xml);
  std::vector<int> wheel_bodies;
  for (const auto& j : robot.urdf.joints)
    if (j.name == robot.wheels.left_joint || j.name == robot.wheels.right_joint)
      wheel_bodies.push_back(measured.body_id(j.child));
  const RobotExtent extent =
      robot_extent(measured.model(), measured.data(), measured.body_id(robot.urdf.root), wheel_bodies);
  robot.footprint_B = extent.footprint;
  robot.rest_height_m = options.root_height_m = kRestClearance_m - extent.lowest_z_m;
  const MjcfRobot mjcf = urdf_to_mjcf(robot.urdf, options);
  robot.mjcf = mjcf.xml;
  robot.mass_kg = mjcf.mass_kg;
  robot.notices = robot.urdf.notices;
  if (!mjcf.held_joints.empty())
    robot.notices.push_back("URDF " + config.urdf +
                            ": joints held at their rest position (the bench moves only the wheels "
                            "and continuous joints): " +
                            joined(mjcf.held_joints));
  // A stand-in inertial on the base or a drive wheel leaves nothing real for the wheel physics to push.
  std::vector<std::string> unusable;
  for (const auto& s : mjcf.stand_in_inertials) {
    const std::string link = s.substr(0, s.find(':'));
    const UrdfJoint* j = robot.urdf.parent_joint(link);
    if (!j || j->name == robot.wheels.left_joint || j->name == robot.wheels.right_joint) unusable.push_back(s);
  }
  robot.drive = config.drive;
  if (config.drive == DriveMode::kPhysics) {
    robot.drive_reason = "robot.drive: physics";
    if (!mjcf.stand_in_inertials.empty())
      robot.drive_reason += " (stand-in inertials of 1 g: " + joined(mjcf.stand_in_inertials) + ")";
  } else if (config.drive == DriveMode::kKinematic) {
    robot.drive_reason = "robot.drive: kinematic";
  } else if (!unusable.empty()) {
    robot.drive = DriveMode::kKinematic;
    robot.drive_reason = "auto: no usable inertial on the base or a wheel (" + joined(unusable) + ")";
  } else {
    robot.drive = DriveMode::kPhysics;
    const Probe probe = probe_physics(robot);
    if (!probe.passed) {
      robot.drive = DriveMode::kKinematic;
      std::string hint;
      if (extent.wheels_lowest_z_m - extent.lowest_z_m > 0.001)
        hint = "; the wheels stand " + fixed(1000 * (extent.wheels_lowest_z_m - extent.lowest_z_m), 1) +
               " mm above the lowest collision shape (" + extent.lowest_geom + ")";
      robot.drive_reason = "auto: " + probe.summary + hint;
    } else {
      robot.drive_reason = "auto: " + probe.summary;
    }
  }
  return robot;
}

World load_world_with_robot(const std::string& world_path, const UrdfRobot& robot) {
  tinyxml2::XMLDocument doc;
  if (doc.LoadFile(world_path.c_str()) == tinyxml2::XML_SUCCESS && !includes_robot_xml(doc.RootElement()))
    throw std::invalid_argument("world '" + world_path + "' has no <include file=\"robot.xml\"/> for the URDF robot (" +
                                robot.config.urdf + ") to stand in for: add one inside <mujoco>");
  try {
    return World::from_file(world_path, {{"robot.xml", robot.mjcf}});
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(std::string(e.what()) + " (with the robot from " + robot.config.urdf + ")");
  }
}

bool is_optical_frame(const std::string& link) {
  const std::string suffix = "_optical_frame";
  return link.size() >= suffix.size() && link.compare(link.size() - suffix.size(), suffix.size(), suffix) == 0;
}

CameraMount camera_mount_at(const robot_description::UrdfModel& urdf, const std::string& frame) {
  Eigen::Isometry3d T = urdf.T_root_link(frame);
  if (is_optical_frame(frame)) T = T * DiffDriveRobot::T_camera_link_optical().inverse();
  const Eigen::Matrix3d& R = T.linear();
  CameraMount m;
  m.forward_offset_m = T.translation().x();
  m.lateral_offset_m = T.translation().y();
  m.height_m = T.translation().z();
  m.pitch_rad = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  if (std::abs(R(2, 0)) < 1.0 - 1e-12) {
    m.roll_rad = std::atan2(R(2, 1), R(2, 2));
    m.yaw_rad = std::atan2(R(1, 0), R(0, 0));
  } else {  // looking straight up or down: the roll folds into the yaw
    m.yaw_rad = std::atan2(-R(0, 1), R(1, 1));
  }
  return m;
}

}  // namespace stvl::sim

#include "sim/urdf_mjcf.hpp"

#include <charconv>
#include <cmath>
#include <map>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <tinyxml2.h>

namespace stvl::sim {
namespace {

constexpr double kStandInMass_kg = 1e-3;
constexpr double kStandInInertia_kgm2 = 1e-7;
constexpr double kWheelTimeConstant_s = 0.016;  // robot.xml's: kv 4 for 20 kg on 0.08 m wheels
constexpr double kMaxLinearSpeed_mps = 1.2;     // DiffDriveConfig's default limit

// Shortest text that reads back to the same doubles.
std::string numbers(std::initializer_list<double> values) {
  std::string text;
  for (double v : values) {
    char buffer[32];
    const auto end = std::to_chars(buffer, buffer + sizeof buffer, v == 0.0 ? 0.0 : v).ptr;
    text += (text.empty() ? "" : " ") + std::string(buffer, end);
  }
  return text;
}

std::string vector_text(const Eigen::Vector3d& v) { return numbers({v.x(), v.y(), v.z()}); }

std::string quat_text(const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  return numbers({q.w(), q.x(), q.y(), q.z()});
}

// A usable inertial as MuJoCo's principal axes (quaternion, diagonal), or why it is not usable.
struct Principal {
  Eigen::Matrix3d R_link_principal;
  Eigen::Vector3d diagonal;
  std::string problem;  // empty: usable
};

Principal principal(const UrdfInertial& in) {
  Principal p;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(in.inertia_kgm2);
  Eigen::Matrix3d axes = eigen.eigenvectors();
  if (axes.determinant() < 0) axes.col(2) *= -1.0;
  p.R_link_principal = in.T_link_inertial.linear() * axes;
  p.diagonal = eigen.eigenvalues();
  const Eigen::Vector3d& d = p.diagonal;
  const double slack = 1e-9 * d.sum();
  if (!(in.mass_kg > 0)) p.problem = "mass " + numbers({in.mass_kg}) + " kg";
  else if (!(d.minCoeff() > 0)) p.problem = "inertia not positive definite";
  else if (d[0] + d[1] < d[2] - slack) p.problem = "inertia breaks the triangle inequality (A + B >= C)";
  return p;
}

class Writer {
 public:
  Writer(const UrdfModel& urdf, const MjcfRobotOptions& options, MjcfRobot& out)
      : urdf_(urdf), options_(options), out_(out) {
    for (const auto& l : urdf.links)  // the servo gains follow the robot's mass
      if (l.inertial && principal(*l.inertial).problem.empty()) total_mass_ += l.inertial->mass_kg;
  }

  void write() {
    for (const auto& l : urdf_.links)
      for (const auto& c : l.collisions)
        if (c.geometry.shape == UrdfShape::kMesh && !mesh_names_.count(mesh_key(c.geometry)))
          mesh_names_[mesh_key(c.geometry)] = "urdf_mesh_" + std::to_string(mesh_names_.size());
    xml_.OpenElement("mujoco");
    xml_.PushAttribute("model", ("urdf " + urdf_.name).c_str());
    if (!mesh_names_.empty()) {
      xml_.OpenElement("asset");
      for (const auto& [key, name] : mesh_names_) {
        xml_.OpenElement("mesh");
        xml_.PushAttribute("name", name.c_str());
        xml_.PushAttribute("file", key.first.c_str());
        xml_.PushAttribute("scale", key.second.c_str());
        xml_.CloseElement();
      }
      xml_.CloseElement();
    }
    xml_.OpenElement("worldbody");
    Eigen::Isometry3d T_world_root = Eigen::Isometry3d::Identity();
    T_world_root.translation().z() = options_.root_height_m;
    body(*urdf_.find_link(urdf_.root), nullptr, T_world_root);
    xml_.CloseElement();
    actuators();
    xml_.CloseElement();
    out_.xml = xml_.CStr();
    out_.mass_kg = total_mass_;
  }

 private:
  static std::pair<std::string, std::string> mesh_key(const UrdfGeometry& g) {
    return {g.mesh_file, vector_text(g.mesh_scale)};
  }

  void element(const char* name, std::initializer_list<std::pair<const char*, std::string>> attributes) {
    xml_.OpenElement(name);
    for (const auto& [key, value] : attributes) xml_.PushAttribute(key, value.c_str());
    xml_.CloseElement();
  }

  bool driven(const std::string& joint) const {
    return joint == options_.left_wheel_joint || joint == options_.right_wheel_joint;
  }

  // The link's body: pose in its parent body, its joint (null: the root, which gets the freejoint), inertial,
  // geoms, then the bodies of its child links.
  void body(const UrdfLink& link, const UrdfJoint* joint, const Eigen::Isometry3d& T_parent_body) {
    xml_.OpenElement("body");
    xml_.PushAttribute("name", link.name.c_str());
    xml_.PushAttribute("pos", vector_text(T_parent_body.translation()).c_str());
    xml_.PushAttribute("quat", quat_text(T_parent_body.linear()).c_str());
    bool moving = true;
    if (!joint) {
      element("freejoint", {{"name", "base_free"}});
    } else if (joint->type == UrdfJointType::kContinuous || driven(joint->name)) {
      Eigen::Vector3d axis = joint->axis;
      // A driven wheel turns forward for a positive rate: its axis along +y of the root (robot.xml's convention).
      if (driven(joint->name) && (urdf_.T_root_link(link.name).linear() * axis).y() < 0) axis = -axis;
      xml_.OpenElement("joint");
      xml_.PushAttribute("name", joint->name.c_str());
      xml_.PushAttribute("type", "hinge");
      xml_.PushAttribute("axis", vector_text(axis).c_str());
      if (driven(joint->name)) {
        xml_.PushAttribute("armature", numbers({wheel_gain() * options_.timestep_s / 0.4}).c_str());
        xml_.PushAttribute("damping", numbers({joint->damping > 0 ? joint->damping : 0.002}).c_str());
      } else {
        if (joint->damping > 0) xml_.PushAttribute("damping", numbers({joint->damping}).c_str());
        xml_.PushAttribute("armature", "0.0001");
      }
      if (joint->friction > 0) xml_.PushAttribute("frictionloss", numbers({joint->friction}).c_str());
      xml_.CloseElement();
    } else {
      moving = false;
      if (joint->type != UrdfJointType::kFixed)
        out_.held_joints.push_back(joint->name + " (" + type_name(joint->type) + ")");
    }
    inertial(link, moving);
    for (std::size_t k = 0; k < link.collisions.size(); ++k) geom(link, k, joint && driven(joint->name));
    if (!joint) {  // robot.xml's camera sites and camera, moved at run time by DiffDriveRobot::set_camera_mount
      element("site", {{"name", "camera_link"}, {"pos", "0.1 0 0.5"}, {"size", "0.01"}, {"group", "2"}});
      element("site", {{"name", "camera_depth_optical_frame"}, {"pos", "0.1 0 0.5"}, {"xyaxes", "0 -1 0 0 0 -1"},
                       {"size", "0.01"}, {"group", "2"}});
      element("camera", {{"name", "camera_depth"}, {"pos", "0.1 0 0.5"}, {"xyaxes", "0 -1 0 0 0 1"}, {"fovy", "58"}});
    }
    for (const auto& j : urdf_.joints)
      if (j.parent == link.name) body(*urdf_.find_link(j.child), &j, T_parent_child(j, rest_position(j)));
    xml_.CloseElement();
  }

  static const char* type_name(UrdfJointType type) {
    switch (type) {
      case UrdfJointType::kRevolute: return "revolute";
      case UrdfJointType::kPrismatic: return "prismatic";
      case UrdfJointType::kFloating: return "floating";
      case UrdfJointType::kPlanar: return "planar";
      default: return "fixed";
    }
  }

  void inertial(const UrdfLink& link, bool moving) {
    std::string problem = "no <inertial>";
    if (link.inertial) {
      const Principal p = principal(*link.inertial);
      problem = p.problem;
      if (problem.empty()) {
        out_.massive_links.push_back(link.name);
        element("inertial", {{"pos", vector_text(link.inertial->T_link_inertial.translation())},
                             {"quat", quat_text(p.R_link_principal)},
                             {"mass", numbers({link.inertial->mass_kg})},
                             {"diaginertia", vector_text(p.diagonal)}});
        return;
      }
    }
    // Explicit even when massless, or MuJoCo would derive a mass from the geoms (1000 kg/m^3). A moving body
    // needs mass unless a link fixed to it carries some (MuJoCo's rule: base_footprint above base_link).
    bool carried = false;
    for (const auto& j : urdf_.joints)
      if (j.parent == link.name && j.type != UrdfJointType::kContinuous && !driven(j.name)) {
        const UrdfLink& child = *urdf_.find_link(j.child);
        carried = carried || (child.inertial && principal(*child.inertial).problem.empty());
      }
    const bool stand_in = moving && !carried;
    if (stand_in) out_.stand_in_inertials.push_back(link.name + ": " + problem);
    const double mass = stand_in ? kStandInMass_kg : 0.0, inertia = stand_in ? kStandInInertia_kgm2 : 0.0;
    element("inertial", {{"pos", "0 0 0"}, {"mass", numbers({mass})}, {"diaginertia", numbers({inertia, inertia, inertia})}});
  }

  void geom(const UrdfLink& link, std::size_t k, bool wheel) {
    const UrdfCollision& c = link.collisions[k];
    const UrdfGeometry& g = c.geometry;
    xml_.OpenElement("geom");
    xml_.PushAttribute("name", (link.name + "_collision" + (k ? "_" + std::to_string(k) : "")).c_str());
    switch (g.shape) {
      case UrdfShape::kBox:
        xml_.PushAttribute("type", "box");
        xml_.PushAttribute("size", vector_text(0.5 * g.box_size_m).c_str());
        break;
      case UrdfShape::kCylinder:
        xml_.PushAttribute("type", "cylinder");
        xml_.PushAttribute("size", numbers({g.radius_m, 0.5 * g.length_m}).c_str());
        break;
      case UrdfShape::kSphere:
        xml_.PushAttribute("type", "sphere");
        xml_.PushAttribute("size", numbers({g.radius_m}).c_str());
        break;
      case UrdfShape::kMesh:
        xml_.PushAttribute("type", "mesh");
        xml_.PushAttribute("mesh", mesh_names_.at(mesh_key(g)).c_str());
        break;
    }
    xml_.PushAttribute("pos", vector_text(c.T_link_geom.translation()).c_str());
    xml_.PushAttribute("quat", quat_text(c.T_link_geom.linear()).c_str());
    xml_.PushAttribute("group", "2");
    // Drive wheels grip as robot.xml's; everything else touches frictionless (condim 1), as Gazebo descriptions
    // make casters with mu1 = mu2 = 0 in <gazebo> tags that MuJoCo does not read.
    if (wheel) xml_.PushAttribute("friction", "1.2 0.005 0.0001");
    else xml_.PushAttribute("condim", "1");
    xml_.PushAttribute("rgba", wheel ? "0.05 0.05 0.05 1" : "0.3 0.3 0.35 1");
    xml_.CloseElement();
  }

  // Velocity servo gain (N m s/rad): robot.xml's time constant for this robot's mass on these wheels.
  double wheel_gain() const {
    const double mass = std::max(total_mass_, 0.1);
    return mass * options_.wheel_radius_m * options_.wheel_radius_m / 2.0 / kWheelTimeConstant_s;
  }

  void actuators() {
    if (options_.left_wheel_joint.empty()) return;
    const double torque = 0.5 * std::max(total_mass_, 0.1) * 9.81 * options_.wheel_radius_m;
    const double rate = 2.0 * kMaxLinearSpeed_mps / options_.wheel_radius_m;
    xml_.OpenElement("actuator");
    for (const auto& [name, joint] : {std::pair<const char*, std::string>{"left_wheel", options_.left_wheel_joint},
                                      {"right_wheel", options_.right_wheel_joint}})
      element("velocity", {{"name", name}, {"joint", joint}, {"kv", numbers({wheel_gain()})},
                           {"ctrllimited", "true"}, {"ctrlrange", numbers({-rate, rate})},
                           {"forcelimited", "true"}, {"forcerange", numbers({-torque, torque})}});
    xml_.CloseElement();
  }

  const UrdfModel& urdf_;
  const MjcfRobotOptions& options_;
  MjcfRobot& out_;
  tinyxml2::XMLPrinter xml_;
  std::map<std::pair<std::string, std::string>, std::string> mesh_names_;
  double total_mass_ = 0.0;
};

}  // namespace

MjcfRobot urdf_to_mjcf(const UrdfModel& urdf, const MjcfRobotOptions& options) {
  for (const std::string* name : {&options.left_wheel_joint, &options.right_wheel_joint}) {
    if (name->empty()) continue;
    bool ok = false;
    for (const auto& j : urdf.joints)
      ok = ok || (j.name == *name && (j.type == UrdfJointType::kContinuous || j.type == UrdfJointType::kRevolute));
    if (!ok) throw std::invalid_argument(urdf.file + ": no continuous or revolute joint named '" + *name + "' to drive");
  }
  if (!(options.wheel_radius_m > 0)) throw std::invalid_argument("urdf_to_mjcf: wheel_radius_m must be > 0");
  MjcfRobot out;
  Writer(urdf, options, out).write();
  return out;
}

}  // namespace stvl::sim

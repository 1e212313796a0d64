#include "robot_description/urdf_mjcf.hpp"

#include <cmath>
#include <map>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "robot_description/mjcf_writer.hpp"

namespace stvl::robot_description {
namespace {

constexpr double kStandInMass_kg = 1e-3;
constexpr double kStandInInertia_kgm2 = 1e-7;
constexpr double kWheelTimeConstant_s = 0.016;  // robot.xml's: kv 4 for 20 kg on 0.08 m wheels
constexpr double kMaxLinearSpeed_mps = 1.2;     // DiffDriveConfig's default limit

std::string vector_text(const Eigen::Vector3d& v) { return shortest_numbers({v.x(), v.y(), v.z()}); }

std::string quat_text(const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  return shortest_numbers({q.w(), q.x(), q.y(), q.z()});
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
  if (!(in.mass_kg > 0)) p.problem = "mass " + shortest_number(in.mass_kg) + " kg";
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
    xml_.open("mujoco");
    xml_.attribute("model", "urdf " + urdf_.name);
    if (!mesh_names_.empty()) {
      xml_.open("asset");
      for (const auto& [key, name] : mesh_names_) {
        xml_.open("mesh");
        xml_.attribute("name", name);
        xml_.attribute("file", key.first);
        xml_.attribute("scale", key.second);
        xml_.close();
      }
      xml_.close();
    }
    xml_.open("worldbody");
    Eigen::Isometry3d T_world_root = Eigen::Isometry3d::Identity();
    T_world_root.translation().z() = options_.root_height_m;
    body(*urdf_.find_link(urdf_.root), nullptr, T_world_root);
    xml_.close();
    actuators();
    xml_.close();
    out_.xml = xml_.text();
    out_.mass_kg = total_mass_;
  }

 private:
  static std::pair<std::string, std::string> mesh_key(const UrdfGeometry& g) {
    return {g.mesh_file, vector_text(g.mesh_scale)};
  }

  void element(const char* name, std::initializer_list<std::pair<const char*, std::string>> attributes) {
    xml_.element(name, attributes);
  }

  bool driven(const std::string& joint) const {
    return joint == options_.left_wheel_joint || joint == options_.right_wheel_joint;
  }

  // The link's body: pose in its parent body, its joint (null: the root, which gets the freejoint), inertial,
  // geoms, then the bodies of its child links.
  void body(const UrdfLink& link, const UrdfJoint* joint, const Eigen::Isometry3d& T_parent_body) {
    xml_.open("body");
    xml_.attribute("name", link.name);
    xml_.attribute("pos", vector_text(T_parent_body.translation()));
    xml_.attribute("quat", quat_text(T_parent_body.linear()));
    bool moving = true;
    if (!joint) {
      element("freejoint", {{"name", "base_free"}});
    } else if (joint->type == UrdfJointType::kContinuous || driven(joint->name)) {
      Eigen::Vector3d axis = joint->axis;
      // A driven wheel turns forward for a positive rate: its axis along +y of the root (robot.xml's convention).
      if (driven(joint->name) && (urdf_.T_root_link(link.name).linear() * axis).y() < 0) axis = -axis;
      xml_.open("joint");
      xml_.attribute("name", joint->name);
      xml_.attribute("type", "hinge");
      xml_.attribute("axis", vector_text(axis));
      if (driven(joint->name)) {
        xml_.attribute("armature", shortest_number(wheel_gain() * options_.timestep_s / 0.4));
        xml_.attribute("damping", shortest_number(joint->damping > 0 ? joint->damping : 0.002));
      } else {
        if (joint->damping > 0) xml_.attribute("damping", shortest_number(joint->damping));
        xml_.attribute("armature", "0.0001");
      }
      if (joint->friction > 0) xml_.attribute("frictionloss", shortest_number(joint->friction));
      xml_.close();
    } else {
      moving = false;
      if (joint->type != UrdfJointType::kFixed)
        out_.held_joints.push_back(joint->name + " (" + type_name(joint->type) + ")");
    }
    inertial(link, moving);
    for (std::size_t k = 0; k < link.collisions.size(); ++k) geom(link, k, joint && driven(joint->name));
    if (!joint) {  // robot.xml's camera sites and camera, moved at run time by DiffDriveRobot::set_camera_mount
      element("site", {{"name", "camera_link"}, {"pos", "0.1 0 0.5"}, {"size", "0.01"}, {"group", "2"}});
      element("site", {{"name", "camera_depth_optical_frame"},
                       {"pos", "0.1 0 0.5"},
                       {"xyaxes", "0 -1 0 0 0 -1"},
                       {"size", "0.01"},
                       {"group", "2"}});
      element("camera", {{"name", "camera_depth"}, {"pos", "0.1 0 0.5"}, {"xyaxes", "0 -1 0 0 0 1"}, {"fovy", "58"}});
    }
    for (const auto& j : urdf_.joints)
      if (j.parent == link.name) body(*urdf_.find_link(j.child), &j, T_parent_child(j, rest_position(j)));
    xml_.close();
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
                             {"mass", shortest_number(link.inertial->mass_kg)},
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
    element("inertial", {{"pos", "0 0 0"},
                         {"mass", shortest_number(mass)},
                         {"diaginertia", shortest_numbers({inertia, inertia, inertia})}});
  }

  void geom(const UrdfLink& link, std::size_t k, bool wheel) {
    const UrdfCollision& c = link.collisions[k];
    const UrdfGeometry& g = c.geometry;
    xml_.open("geom");
    xml_.attribute("name", link.name + "_collision" + (k ? "_" + std::to_string(k) : ""));
    switch (g.shape) {
      case UrdfShape::kBox:
        xml_.attribute("type", "box");
        xml_.attribute("size", vector_text(0.5 * g.box_size_m));
        break;
      case UrdfShape::kCylinder:
        xml_.attribute("type", "cylinder");
        xml_.attribute("size", shortest_numbers({g.radius_m, 0.5 * g.length_m}));
        break;
      case UrdfShape::kSphere:
        xml_.attribute("type", "sphere");
        xml_.attribute("size", shortest_number(g.radius_m));
        break;
      case UrdfShape::kMesh:
        xml_.attribute("type", "mesh");
        xml_.attribute("mesh", mesh_names_.at(mesh_key(g)));
        break;
    }
    xml_.attribute("pos", vector_text(c.T_link_geom.translation()));
    xml_.attribute("quat", quat_text(c.T_link_geom.linear()));
    xml_.attribute("group", "2");
    // Drive wheels grip as robot.xml's; everything else touches frictionless (condim 1), as Gazebo descriptions
    // make casters with mu1 = mu2 = 0 in <gazebo> tags that MuJoCo does not read.
    if (wheel) xml_.attribute("friction", "1.2 0.005 0.0001");
    else xml_.attribute("condim", "1");
    xml_.attribute("rgba", wheel ? "0.05 0.05 0.05 1" : "0.3 0.3 0.35 1");
    xml_.close();
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
    xml_.open("actuator");
    for (const auto& [name, joint] : {std::pair<const char*, std::string>{"left_wheel", options_.left_wheel_joint},
                                      {"right_wheel", options_.right_wheel_joint}})
      element("velocity", {{"name", name},
                           {"joint", joint},
                           {"kv", shortest_number(wheel_gain())},
                           {"ctrllimited", "true"},
                           {"ctrlrange", shortest_numbers({-rate, rate})},
                           {"forcelimited", "true"},
                           {"forcerange", shortest_numbers({-torque, torque})}});
    xml_.close();
  }

  const UrdfModel& urdf_;
  const MjcfRobotOptions& options_;
  MjcfRobot& out_;
  MjcfWriter xml_{4};  // tinyxml2::XMLPrinter's layout, which wrote robot.xml before
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
    if (!ok)
      throw std::invalid_argument(urdf.file + ": no continuous or revolute joint named '" + *name + "' to drive");
  }
  if (!(options.wheel_radius_m > 0)) throw std::invalid_argument("urdf_to_mjcf: wheel_radius_m must be > 0");
  MjcfRobot out;
  Writer(urdf, options, out).write();
  return out;
}

}  // namespace stvl::robot_description

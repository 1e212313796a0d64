#pragma once
// A URDF robot description as the bench reads it (tinyxml2): links with their collision shapes and inertials,
// joints with origins and axes, and the tree they form. Visual elements are not used (collision geometry only,
// as MuJoCo's own URDF reader discards visuals). Lengths in metres, angles in radians, transforms T_parent_child.
//   const UrdfModel urdf = load_urdf("worlds/urdf/example_bot/example_bot.urdf", {"worlds/urdf"});
//   const Eigen::Isometry3d T_base_cam = urdf.T_root_link("camera_depth_optical_frame");
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace stvl::robot_description {

enum class UrdfShape { kBox, kCylinder, kSphere, kMesh };

struct UrdfGeometry {
  UrdfShape shape = UrdfShape::kBox;
  Eigen::Vector3d box_size_m = Eigen::Vector3d::Zero();  // kBox: full edge lengths, as URDF writes them
  double radius_m = 0, length_m = 0;                     // kCylinder (axis along its z), kSphere
  std::string mesh_uri;                                  // kMesh: as written in the file
  std::string mesh_file;                                 // kMesh: the resolved absolute path (STL or OBJ)
  Eigen::Vector3d mesh_scale = Eigen::Vector3d::Ones();
};

struct UrdfCollision {
  Eigen::Isometry3d T_link_geom = Eigen::Isometry3d::Identity();
  UrdfGeometry geometry;
};

struct UrdfInertial {
  Eigen::Isometry3d T_link_inertial = Eigen::Isometry3d::Identity();
  double mass_kg = 0;
  Eigen::Matrix3d inertia_kgm2 = Eigen::Matrix3d::Zero();  // about the inertial origin, in its axes
};

struct UrdfLink {
  std::string name;
  int line = 0;
  std::optional<UrdfInertial> inertial;  // none: URDF's massless link
  std::vector<UrdfCollision> collisions;
};

enum class UrdfJointType { kFixed, kRevolute, kContinuous, kPrismatic, kFloating, kPlanar };

struct UrdfJoint {
  std::string name;
  int line = 0;
  UrdfJointType type = UrdfJointType::kFixed;
  std::string parent, child;
  Eigen::Isometry3d T_parent_joint = Eigen::Isometry3d::Identity();  // <origin>: the child's frame at position 0
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();                   // unit, in the joint (child) frame
  bool has_limits = false;
  double lower = 0, upper = 0;  // rad or m, when has_limits
  double damping = 0, friction = 0;
};

struct UrdfModel {
  std::string file;  // as given; every message starts with it
  std::string name;
  std::vector<UrdfLink> links;       // file order
  std::vector<UrdfJoint> joints;     // file order
  std::string root;                  // the one link no joint has as its child
  std::vector<std::string> notices;  // what was skipped, one line each (a visual DAE mesh: the links)

  // The link or joint named so; null when there is none.
  const UrdfLink* find_link(const std::string& name) const;
  // The joint whose child is `link`; null for the root (or an unknown name).
  const UrdfJoint* parent_joint(const std::string& link) const;
  // `link` in the root link's frame with every joint at its rest position (0, clamped into a revolute or
  // prismatic joint's limits). Throws std::invalid_argument for an unknown link (see unknown_link_message).
  Eigen::Isometry3d T_root_link(const std::string& link) const;
  // "FILE: no link named 'X' (links, nearest first: a, b, ...)".
  std::string unknown_link_message(const std::string& name) const;
};

// The rest position of a joint: 0, clamped into [lower, upper] when it has limits.
double rest_position(const UrdfJoint& joint);
// The child's frame in the parent's at `position` (rad or m along the axis); fixed and floating joints ignore it.
Eigen::Isometry3d T_parent_child(const UrdfJoint& joint, double position);
// URDF's rpy: R = Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Matrix3d rpy_to_matrix(const Eigen::Vector3d& rpy);

// Parses URDF text. Collision meshes are resolved (package_path.hpp: package://, file://, relative to the
// folder of `file`) and must be STL (binary) or OBJ; visuals are skipped (a DAE visual adds one notice naming the
// links). Throws std::invalid_argument "FILE:LINE: what; how to fix" for malformed XML (tinyxml2's error and
// line), a missing or malformed attribute, an unknown joint type or shape, a collision mesh that is missing,
// DAE or ASCII STL, a joint naming an unknown link, a link with two parents, a loop, or not exactly one root.
UrdfModel parse_urdf(const std::string& text, const std::string& file, const std::vector<std::string>& package_path);
// Reads the file, then parse_urdf. Throws std::invalid_argument when it cannot be read.
UrdfModel load_urdf(const std::string& path, const std::vector<std::string>& package_path);

}  // namespace stvl::robot_description

#pragma once
// MJCF text for the worlds worldgen builds, with the header conventions of worlds/office_corridor.xml (statistic
// extent 1 so znear/zfar are absolute, MSAA off, the robot included from robot.xml beside the world), and the
// robot's footprint radius read from robot.xml. Written through robot_description's MjcfWriter, the robot's too;
// numbers are written with fixed precision, so the same world always gives the same bytes.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robot_description/mjcf_writer.hpp"

namespace stvl::worldgen {

// Geom groups: walls, doors and the floor 0; furniture and people 1 (the robot's are 2 and 3, sim/world.hpp).
inline constexpr int kWallGroup = 0;
inline constexpr int kObstacleGroup = 1;

// One primitive geom in its body's frame. size: box half extents (3), cylinder radius and half height (2),
// sphere radius (1), capsule radius (1, with fromto), ellipsoid radii (3).
struct Geom {
  std::string type;  // box, cylinder, sphere, capsule, ellipsoid
  std::string name;  // may be empty
  Eigen::Vector3d pos = Eigen::Vector3d::Zero();
  std::vector<double> size;
  std::vector<double> fromto;  // capsules: 6 numbers instead of pos
  double yaw_rad = 0;          // about the body's z
  int group = kObstacleGroup;
  std::string rgba = "0.6 0.6 0.6 1";
};

struct Body {
  std::string name;
  std::string comment;  // written above the body when not empty
  Eigen::Vector3d pos = Eigen::Vector3d::Zero();
  double yaw_rad = 0;
  bool mocap = false;
  std::vector<Geom> geoms;
};

struct WorldSpec {
  std::string model_name;
  std::string comment;  // the world's description, a comment at its top
  Eigen::Vector2d floor_min_W = Eigen::Vector2d::Zero(),
                  floor_max_W = Eigen::Vector2d::Zero();  // the floor plane's extent
  std::vector<Body> bodies;
};

// The world as MJCF text: header, <include file="robot.xml"/>, a light, the floor, the bodies.
std::string write_mjcf(const WorldSpec& world);

// `value` with `decimals` digits after the point, "-0.000" written as "0.000" (robot_description/mjcf_writer.hpp).
using robot_description::fixed;

// worlds/robot.xml of this checkout: the robot every generated world includes.
std::string shipped_robot_xml();

// The radius of the robot's footprint about base_link: the farthest horizontal reach of its geoms (groups 2 and
// 3) from base_link's origin, read from a robot MJCF file such as worlds/robot.xml (0.29 m: the front bumper's
// corners). Throws std::runtime_error naming the file when MuJoCo cannot load it or it has no base_link.
double robot_footprint_radius_m(const std::string& robot_xml_path);

}  // namespace stvl::worldgen

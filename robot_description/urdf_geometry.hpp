#pragma once
// The extent of a robot compiled in MuJoCo at its current pose: how low it reaches (its rest height on the
// floor) and its outline projected on the floor (the footprint of a URDF robot). Lengths in metres, world frame.
#include <string>
#include <vector>

#include <mujoco/mujoco.h>
#include <Eigen/Geometry>

namespace stvl::robot_description {

struct RobotExtent {
  double lowest_z_m = 0;                   // the lowest point of any geom of the robot
  std::string lowest_geom;                 // whose it is (a name, or "geom N")
  double wheels_lowest_z_m = 0;            // the lowest point of the wheel bodies' geoms (lowest_z_m without wheels)
  std::vector<Eigen::Vector2d> footprint;  // convex hull of every geom projected on x-y, counter-clockwise
};

// The geoms of the bodies below and at root_body: exact lowest points (boxes, spheres, capsules, cylinders,
// ellipsoids, mesh vertices) and their outlines (circles as circumscribed 32-gons, meshes by their vertices).
RobotExtent robot_extent(const mjModel* m, const mjData* d, int root_body, const std::vector<int>& wheel_bodies);

// The convex hull of `points`, counter-clockwise from the lowest-x point; corners less than 0.1 mm off the line
// through their neighbours are dropped. Fewer than three distinct points come back as they are (deduplicated).
std::vector<Eigen::Vector2d> convex_hull(std::vector<Eigen::Vector2d> points);

}  // namespace stvl::robot_description

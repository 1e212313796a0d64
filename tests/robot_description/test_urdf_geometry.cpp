// robot_description/urdf_geometry.hpp: the convex hull of a robot's outline (robot_extent runs through
// tests/sim/test_urdf_robot.cpp, on robots MuJoCo compiled).
#include <gtest/gtest.h>

#include <vector>

#include <Eigen/Core>

#include "robot_description/urdf_geometry.hpp"

namespace stvl::robot_description {
namespace {

TEST(ConvexHull, CornersOnlyCounterClockwise) {
  // A square with points inside, repeated, on its edges and 0.05 mm off an edge: its four corners are left.
  const std::vector<Eigen::Vector2d> hull =
      convex_hull({{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5, 0.5}, {1, 1}, {0.5, 0}, {1, 0.3}, {0.4, 1.00005}, {0.2, 0.7}});
  ASSERT_EQ(hull.size(), 4u);
  EXPECT_EQ(hull[0], Eigen::Vector2d(0, 0));
  EXPECT_EQ(hull[1], Eigen::Vector2d(1, 0));
  EXPECT_EQ(hull[2], Eigen::Vector2d(1, 1));
  EXPECT_EQ(hull[3], Eigen::Vector2d(0, 1));
  EXPECT_EQ(convex_hull({{1, 2}, {1, 2}}).size(), 1u);
}

}  // namespace
}  // namespace stvl::robot_description

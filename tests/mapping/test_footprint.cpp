// STVL's footprint clearing (update_footprint_enabled): the costmap cells of the footprint's convex fill are
// freed whatever the heights of their voxels; cells outside stay lethal; the voxels stay in the map.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>

#include "mapping/footprint.hpp"
#include "mapping/voxel_map.hpp"

namespace stvl::mapping {
namespace {

Eigen::Isometry3d pose(double x, double y, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 0.0);
  return T;
}

TEST(Footprint, FromRadiusIsNav2sSixteenPoints) {
  const auto points = footprint_from_radius(0.3);
  ASSERT_EQ(points.size(), 16u);
  EXPECT_NEAR(points[0].x(), 0.3, 1e-12);
  EXPECT_NEAR(points[0].y(), 0.0, 1e-12);
  EXPECT_NEAR(points[4].y(), 0.3, 1e-12);  // counter-clockwise
  for (const auto& p : points) EXPECT_NEAR(p.norm(), 0.3, 1e-12);
  EXPECT_THROW(footprint_from_radius(0.0), std::invalid_argument);
  EXPECT_THROW(footprint_from_radius(-0.2), std::invalid_argument);
  EXPECT_THROW(footprint_from_radius(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
}

TEST(Footprint, MovesWithTheRobotsYaw) {
  const std::vector<Eigen::Vector2d> front{{0.5, 0.0}, {0.0, 0.2}, {0.0, -0.2}};
  const auto w = footprint_in_world(front, pose(1.0, 2.0, M_PI / 2));
  EXPECT_NEAR(w[0].x(), 1.0, 1e-12);
  EXPECT_NEAR(w[0].y(), 2.5, 1e-12);
  EXPECT_NEAR(w[1].x(), 0.8, 1e-12);
}

TEST(Footprint, CellsAreNav2sConvexFill) {
  // A square from 0.01 to 0.35 m at 0.1 m cells: vertex cells 0 and 3, so columns 0..3 and rows 0..3 (the
  // outline cells included, as nav2's convexFillCells takes them).
  const std::vector<Eigen::Vector2d> square{{0.01, 0.01}, {0.35, 0.01}, {0.35, 0.35}, {0.01, 0.35}};
  const auto cells = footprint_cells(square, Eigen::Vector2d::Zero(), 0.1);
  EXPECT_EQ(cells.size(), 16u);
  // A triangle: the column of its apex holds one cell, the columns of its base edge all rows between.
  const std::vector<Eigen::Vector2d> triangle{{0.05, 0.05}, {0.45, 0.25}, {0.05, 0.45}};
  std::set<std::array<int, 2>> t;
  for (const auto& c : footprint_cells(triangle, Eigen::Vector2d::Zero(), 0.1)) t.insert(c);
  EXPECT_TRUE(t.count({0, 0}) && t.count({0, 2}) && t.count({0, 4}));
  EXPECT_TRUE(t.count({4, 2}));
  EXPECT_FALSE(t.count({4, 0}) || t.count({4, 4}) || t.count({3, 0}));
  EXPECT_TRUE(footprint_cells({{0, 0}, {1, 1}}, Eigen::Vector2d::Zero(), 0.1).empty());  // under 3 points
}

TEST(Footprint, ClearingFreesTheFootprintsCellsAtAnyHeightAndKeepsTheVoxels) {
  StvlConfig config;
  config.voxel_size_m = 0.05;
  VoxelMap map(config);
  const Eigen::Isometry3d T_world_base = pose(1.0, 1.0, 0.5);
  // Columns inside the robot's 0.25 m circle at three heights in the band, and columns 0.4 m away.
  std::vector<Voxel> voxels;
  const auto key_at = [&](const Eigen::Vector3d& p_B) {
    const Eigen::Vector3d p_W = T_world_base * p_B;
    return VoxelKey{int(std::floor(p_W.x() / 0.05)), int(std::floor(p_W.y() / 0.05)), int(std::floor(p_W.z() / 0.05))};
  };
  const std::vector<Eigen::Vector3d> inside_B{{0.2, 0.0, 0.07}, {0.0, 0.0, 0.5}, {-0.1, 0.15, 1.5}, {0.0, -0.2, 0.12}};
  const std::vector<Eigen::Vector3d> outside_B{{0.4, 0.0, 0.07}, {-0.4, 0.1, 0.5}, {0.0, 0.42, 1.5}};
  for (const auto& p : inside_B) voxels.push_back({key_at(p), 1.0});
  for (const auto& p : outside_B) voxels.push_back({key_at(p), 1.0});
  map.set_voxels(voxels);
  const std::size_t before = map.size();

  CostmapOptions options;
  options.bounds_W = Eigen::AlignedBox2d(Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(2.0, 2.0));
  const auto cost_at = [](const Costmap2D& c, const Eigen::Vector3d& p_W) { return *c.at_world(p_W.x(), p_W.y()); };
  const Costmap2D plain = map.project_costmap(options);
  for (const auto& p : inside_B) EXPECT_EQ(cost_at(plain, T_world_base * p), kCostLethal);

  options.free_polygon_W = footprint_in_world(footprint_from_radius(0.25), T_world_base);
  const Costmap2D cleared = map.project_costmap(options);
  for (const auto& p : inside_B) EXPECT_EQ(cost_at(cleared, T_world_base * p), kCostFree) << p.transpose();
  for (const auto& p : outside_B) EXPECT_EQ(cost_at(cleared, T_world_base * p), kCostLethal) << p.transpose();
  EXPECT_EQ(map.size(), before);  // STVL frees the costmap's cells only

  // A polygon footprint: a rectangle 0.3 m ahead, the robot turned: the columns at 0.2 m ahead free, the one
  // 0.4 m ahead lethal.
  options.free_polygon_W = footprint_in_world({{0.3, 0.25}, {-0.3, 0.25}, {-0.3, -0.25}, {0.3, -0.25}}, T_world_base);
  const Costmap2D rectangle = map.project_costmap(options);
  EXPECT_EQ(cost_at(rectangle, T_world_base * inside_B[0]), kCostFree);
  EXPECT_EQ(cost_at(rectangle, T_world_base * outside_B[0]), kCostLethal);

  // The costmap over the occupied extent only: a footprint partly outside it is clipped.
  CostmapOptions extent;
  extent.free_polygon_W = footprint_in_world(footprint_from_radius(0.25), pose(-5.0, -5.0, 0.0));
  EXPECT_EQ(map.project_costmap(extent).at_world(T_world_base.translation().x() + 0.4 * std::cos(0.5),
                                                 T_world_base.translation().y() + 0.4 * std::sin(0.5)),
            kCostLethal);
}

TEST(Footprint, ConfigRejectsShortOrNonFinitePolygons) {
  StvlConfig config;
  config.footprint_B = {{0.1, 0.0}, {0.0, 0.1}};
  EXPECT_THROW(config.validate(), std::invalid_argument);
  config.footprint_B.push_back({std::numeric_limits<double>::infinity(), 0.0});
  EXPECT_THROW(config.validate(), std::invalid_argument);
  config.footprint_B.back() = {-0.1, 0.0};
  EXPECT_NO_THROW(config.validate());
}

}  // namespace
}  // namespace stvl::mapping

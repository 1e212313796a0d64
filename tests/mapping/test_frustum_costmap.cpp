#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "mapping/costmap.hpp"
#include "mapping/frustum.hpp"
#include "mapping/reference/costmap_reference.hpp"
#include "mapping/voxel_map.hpp"
#include "test_helpers.hpp"

namespace stvl::mapping {
namespace {

using test::camera_looking_along_x;

TEST(DepthCameraFrustum, ContainsFollowsFovAndRange) {
  // 90 deg horizontal, 60 deg vertical, 0.5..4 m, camera at (1, 2, 0.5) looking along +x.
  const DepthCameraFrustum f(camera_looking_along_x({1, 2, 0.5}), 1.5707963267948966, 1.0471975511965976, 0.5, 4.0);
  EXPECT_TRUE(f.contains({3.0, 2.0, 0.5}));
  EXPECT_FALSE(f.contains({1.4, 2.0, 0.5}));        // nearer than min_z
  EXPECT_FALSE(f.contains({5.1, 2.0, 0.5}));        // beyond max_z
  EXPECT_FALSE(f.contains({-1.0, 2.0, 0.5}));       // behind
  EXPECT_TRUE(f.contains({3.0, 2.0 + 1.99, 0.5}));  // 45 deg half angle: |dy| < dx
  EXPECT_FALSE(f.contains({3.0, 2.0 + 2.01, 0.5}));
  EXPECT_TRUE(f.contains({3.0, 2.0, 0.5 - 1.15}));   // 30 deg half angle: |dz| < dx * 0.577
  EXPECT_FALSE(f.contains({3.0, 2.0, 0.5 + 1.17}));  // up and down are symmetric (no sign slip)
  EXPECT_FALSE(f.contains({3.0, 2.0, 0.5 - 1.17}));

  EXPECT_TRUE(f.may_intersect(Eigen::AlignedBox3d(Eigen::Vector3d(2, 1, 0), Eigen::Vector3d(3, 3, 1))));
  EXPECT_FALSE(f.may_intersect(Eigen::AlignedBox3d(Eigen::Vector3d(-3, 1, 0), Eigen::Vector3d(0, 3, 1))));
  EXPECT_FALSE(f.may_intersect(Eigen::AlignedBox3d(Eigen::Vector3d(2, 6, 0), Eigen::Vector3d(3, 7, 1))));
  EXPECT_THROW(DepthCameraFrustum(camera_looking_along_x({0, 0, 0}), 0.0, 1.0, 0.1, 1.0), std::invalid_argument);
  EXPECT_THROW(DepthCameraFrustum(camera_looking_along_x({0, 0, 0}), 1.0, 1.0, 2.0, 1.0), std::invalid_argument);
}

// Columns (at voxel_size 0.1): A at (0.05, 0.05) with 3 voxels, B at (0.35, 0.05) with 1 voxel,
// C at (0.05, 0.25) with 2 voxels of which one is above the 1 m band.
VoxelMap layout(int mark_threshold) {
  StvlConfig config;
  config.voxel_size_m = 0.1;
  config.mark_threshold = mark_threshold;
  VoxelMap map(config);
  map.set_voxels(
      {{{0, 0, 0}, 1.0}, {{0, 0, 1}, 1.0}, {{0, 0, 2}, 1.0}, {{3, 0, 0}, 1.0}, {{0, 2, 0}, 1.0}, {{0, 2, 15}, 1.0}});
  return map;
}

TEST(Costmap, ProjectsColumnsWithMarkThreshold) {
  CostmapOptions options;
  options.max_obstacle_height_m = 1.0;
  const Costmap2D zero = layout(0).project_costmap(options);  // STVL: 0 behaves like 1
  EXPECT_EQ(zero.width, 4);
  EXPECT_EQ(zero.height, 3);
  EXPECT_DOUBLE_EQ(zero.origin_m.x(), 0.0);
  EXPECT_DOUBLE_EQ(zero.origin_m.y(), 0.0);
  EXPECT_EQ(zero.at(0, 0), kCostLethal);
  EXPECT_EQ(zero.at(3, 0), kCostLethal);
  EXPECT_EQ(zero.at(0, 2), kCostLethal);
  EXPECT_EQ(zero.at(1, 0), kCostFree);
  EXPECT_EQ(zero.at(1, 1), kCostFree);

  const Costmap2D two = layout(2).project_costmap(options);
  EXPECT_EQ(two.at(0, 0), kCostLethal);  // 3 voxels
  EXPECT_EQ(two.at(3, 0), kCostFree);    // 1 voxel
  EXPECT_EQ(two.at(0, 2), kCostFree);    // 2 voxels but one outside the band
  options.max_obstacle_height_m = 2.0;
  EXPECT_EQ(layout(2).project_costmap(options).at(0, 2), kCostLethal);
  EXPECT_EQ(layout(3).project_costmap(options).at(0, 2), kCostFree);
  EXPECT_EQ(layout(3).project_costmap(options).at(0, 0), kCostLethal);

  CostmapOptions bounded;
  bounded.bounds_W = Eigen::AlignedBox2d(Eigen::Vector2d(-1.0, -1.0), Eigen::Vector2d(1.0, 1.0));
  bounded.resolution_m = 0.2;
  const Costmap2D coarse = layout(0).project_costmap(bounded);
  EXPECT_EQ(coarse.width, 10);
  EXPECT_EQ(coarse.height, 10);
  EXPECT_EQ(coarse.at_world(0.05, 0.05), kCostLethal);
  EXPECT_EQ(coarse.at_world(0.35, 0.05), kCostLethal);
  EXPECT_EQ(coarse.at_world(-0.5, -0.5), kCostFree);
  EXPECT_FALSE(coarse.at_world(1.5, 0.0).has_value());
  bounded.resolution_m = -1.0;
  EXPECT_THROW(layout(0).project_costmap(bounded), std::invalid_argument);
}

// project_costmap() counts a leaf's columns at once; its plain twin, one voxel at a time, over random maps
// that span several leaves and negative keys, with and without bounds, at the voxel size and a coarser one.
TEST(Costmap, LeafWiseProjectionEqualsTheVoxelByVoxelDefinition) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> xy(-12, 12), z(-3, 25), threshold(0, 3);
  for (int trial = 0; trial < 20; ++trial) {
    StvlConfig config;
    config.voxel_size_m = 0.05;
    config.mark_threshold = threshold(rng);
    VoxelMap map(config);
    std::vector<Voxel> voxels;
    for (int i = 0; i < 1500; ++i) voxels.push_back({{xy(rng), xy(rng), z(rng)}, 1.0});
    map.set_voxels(voxels);
    CostmapOptions options;
    options.min_obstacle_height_m = 0.1;
    options.max_obstacle_height_m = 0.8;
    options.resolution_m = trial % 2 ? 0.05 : 0.15;
    if (trial % 4 == 3) options.bounds_W = Eigen::AlignedBox2d(Eigen::Vector2d(-0.6, -0.4), Eigen::Vector2d(0.5, 0.7));
    const Costmap2D projected = map.project_costmap(options);
    // The definition (mapping/reference/): each voxel centre in the band adds one to the cell holding it; lethal
    // at >= max(threshold, 1).
    std::size_t outside = 0;
    const std::vector<int> counts = reference::costmap_column_counts(map, options, projected, &outside);
    if (!options.bounds_W) {
      EXPECT_EQ(outside, 0u) << "the map's extent holds every column";
    }
    std::size_t lethal = 0;
    for (std::size_t i = 0; i < counts.size(); ++i) {
      const bool expected = counts[i] >= std::max(config.mark_threshold, 1);
      ASSERT_EQ(projected.cells[i] == kCostLethal, expected) << "trial " << trial << " cell " << i;
      lethal += expected;
    }
    EXPECT_GT(lethal, 0u) << "trial " << trial;  // not vacuous
  }
}

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

TEST(Costmap, WritesPgmAndMapServerYaml) {
  CostmapOptions options;
  options.max_obstacle_height_m = 1.0;
  const Costmap2D map = layout(0).project_costmap(options);
  const std::string base = ::testing::TempDir() + "stvl_costmap_test";
  write_costmap(map, base);
  const std::string pgm = read_all(base + ".pgm");
  const std::string header = "P5\n4 3\n255\n";
  ASSERT_EQ(pgm.size(), header.size() + 12);
  EXPECT_EQ(pgm.substr(0, header.size()), header);
  const auto pixel = [&](int row, int col) { return static_cast<unsigned char>(pgm[header.size() + row * 4 + col]); };
  EXPECT_EQ(pixel(2, 0), 0);    // bottom row = lowest y: column A is lethal (black)
  EXPECT_EQ(pixel(2, 3), 0);    // B
  EXPECT_EQ(pixel(0, 0), 0);    // C on the top row
  EXPECT_EQ(pixel(2, 1), 254);  // free (white)
  const std::string yaml = read_all(base + ".yaml");
  EXPECT_NE(yaml.find("image: stvl_costmap_test.pgm"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("resolution: 0.1"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("origin: [0, 0, 0.0]"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("mode: trinary"), std::string::npos);
  EXPECT_NE(yaml.find("negate: 0"), std::string::npos);
  EXPECT_NE(yaml.find("occupied_thresh: 0.65"), std::string::npos);
  EXPECT_NE(yaml.find("free_thresh: 0.196"), std::string::npos);
  EXPECT_FALSE(std::ifstream(base + ".pgm.tmp").good());
  EXPECT_THROW(write_costmap(map, "/nonexistent-dir/x"), std::runtime_error);
}

}  // namespace
}  // namespace stvl::mapping

// Exact truth of meshes and height fields against its brute-force twin (truth/reference/): the same voxels, solids
// and cells for closed bumpy spheres, triangle soups, lattice-aligned meshes and a bumpy height field.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "tests/support/fixture.hpp"
#include "tests/truth/mesh_truth_helpers.hpp"
#include "truth/ground_truth.hpp"
#include "truth/mesh_voxelize.hpp"
#include "truth/reference/mesh_voxelize_reference.hpp"

namespace stvl::truth {
namespace {

using namespace mesh_test;
using sim::World;

std::vector<detail::Triangle> world_triangles(const ObstacleGeom& g) {
  std::vector<detail::Triangle> out;
  for (std::size_t f = 0; f < g.mesh->faces().size(); ++f) {
    const auto t = g.mesh->triangle(f);
    out.push_back({g.T_world_geom * t[0], g.T_world_geom * t[1], g.T_world_geom * t[2]});
  }
  return out;
}

void expect_matches_reference(const ObstacleGeom& g, double s, const std::string& what) {
  const auto triangles = world_triangles(g);
  const bool closed = g.mesh->closed();
  const Eigen::AlignedBox3d everywhere(Eigen::Vector3d::Constant(-1e6), Eigen::Vector3d::Constant(1e6));
  std::size_t solid_count = 0;
  for (const bool solid : {false, true}) {
    const auto fast = voxels(g, s, solid);
    const auto plain = reference::voxelize_triangles(triangles, closed, s, solid, g.aabb_W().intersection(everywhere));
    EXPECT_EQ(fast, plain) << what << (solid ? " solid" : " surface") << ": " << fast.size() << " vs " << plain.size();
    EXPECT_FALSE(fast.empty()) << what;
    if (solid) solid_count = fast.size();
  }
  const Eigen::AlignedBox3d box = g.aabb_W();
  const double z0 = box.min().z() + 0.3 * box.sizes().z(), z1 = box.min().z() + 0.6 * box.sizes().z();
  EXPECT_EQ(cells(g, s, z0, z1), reference::footprint_triangles(triangles, closed, s, z0, z1)) << what << " cells";
  if (closed) {
    EXPECT_GT(solid_count, voxels(g, s, false).size()) << what << ": the solid has an inside";
  }
}

TEST(MeshTruthReference, ClosedBumpySpheresMatch) {
  std::mt19937 rng(29);
  for (int trial = 0; trial < 4; ++trial) {
    std::uniform_real_distribution<double> a(-M_PI, M_PI), t(-1, 1);
    const ObstacleGeom g = bumpy_sphere(rng, 7 + trial, 9 + 2 * trial, 0.3 + 0.05 * trial, 0.25,
                                        pose({t(rng), t(rng), 0.5 + t(rng)}, a(rng), a(rng)));
    ASSERT_TRUE(g.mesh->closed());
    expect_matches_reference(g, trial % 2 ? 0.05 : 0.07, "bumpy sphere " + std::to_string(trial));
  }
}

TEST(MeshTruthReference, TriangleSoupsMatch) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (int trial = 0; trial < 4; ++trial) {
    std::vector<Eigen::Vector3d> v;
    std::vector<TriangleMesh::Face> f;
    for (int k = 0; k < 25; ++k) {
      const Eigen::Vector3d c(u(rng), u(rng), u(rng));
      const double size = k % 5 == 0 ? 0.8 : 0.15;  // a few large slanted ones among small ones
      for (int i = 0; i < 3; ++i) v.push_back(c + size * Eigen::Vector3d(u(rng), u(rng), u(rng)));
      f.push_back({3 * k, 3 * k + 1, 3 * k + 2});
    }
    v.push_back({0.1, 0.1, 0.1});  // and a degenerate one (a segment)
    v.push_back({0.3, 0.2, 0.1});
    f.push_back({75, 76, 76});
    const ObstacleGeom g = mesh_geom(v, f, pose({0.2, -0.1, 0.3}, 0.1 * trial, 0.2));
    EXPECT_FALSE(g.mesh->closed());
    expect_matches_reference(g, 0.05, "soup " + std::to_string(trial));
  }
}

TEST(MeshTruthReference, LatticeAlignedClosedMeshesMatch) {
  // Vertices on voxel centres and corners: the vertical lines of the solid pass next to edges and vertices.
  const double s = 0.05;
  std::vector<Eigen::Vector3d> corners = {{0.025, 0.025, 0.025}, {0.225, 0.025, 0.025}, {0.025, 0.175, 0.025},
                                          {0.225, 0.175, 0.025}, {0.025, 0.025, 0.225}, {0.225, 0.025, 0.225},
                                          {0.025, 0.175, 0.225}, {0.225, 0.175, 0.225}};
  const std::vector<TriangleMesh::Face> box_faces = {{0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}, {0, 1, 5}, {0, 5, 4},
                                                     {2, 6, 7}, {2, 7, 3}, {0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}};
  expect_matches_reference(mesh_geom(corners, box_faces), s, "box on centres");
  for (auto& c : corners) c -= Eigen::Vector3d::Constant(0.025);
  expect_matches_reference(mesh_geom(corners, box_faces), s, "box on corners");
  // An octahedron with its apexes on voxel centres.
  const std::vector<Eigen::Vector3d> octa = {{0.325, 0.025, 0.025},  {-0.275, 0.025, 0.025}, {0.025, 0.325, 0.025},
                                             {0.025, -0.275, 0.025}, {0.025, 0.025, 0.325},  {0.025, 0.025, -0.275}};
  expect_matches_reference(
      mesh_geom(octa, {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}}), s,
      "octahedron");
}

TEST(MeshTruth, BumpyHeightFieldMatchesTheReference) {
  World world = World::from_string(kHeightFieldWorld);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0, 1);
  float* data = world.mutable_model()->hfield_data;
  for (int i = 0; i < 35; ++i) data[i] = u(rng);
  world.forward();
  const ObstacleGeom g = obstacle_geoms(world).at(0);
  EXPECT_TRUE(g.mesh->closed());
  EXPECT_EQ(g.mesh->faces().size(), 4u * 4 * 6 + 4u * 4 + 4u * 6);
  expect_matches_reference(g, 0.05, "height field");
  // The top is where the data says: sample (row 2, column 3) is the geom's centre.
  EXPECT_NEAR(g.signed_distance_m({0.3, 0.2, 0.213 + 0.4 * data[2 * 7 + 3]}), 0.0, 1e-6);
}

}  // namespace
}  // namespace stvl::truth

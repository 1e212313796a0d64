// Exact truth of meshes and height fields (truth/ground_truth.hpp, truth/mesh_voxelize.hpp): against the box primitive
// and hand-computed voxels and cells; test_mesh_truth_reference.cpp compares with the brute-force twin.
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>

#include "tests/support/fixture.hpp"
#include "tests/truth/mesh_truth_helpers.hpp"
#include "truth/ground_truth.hpp"
#include "truth/mesh_voxelize.hpp"

namespace stvl::truth {
namespace {

using namespace mesh_test;
using sim::World;

// A box [0.01, 0.99] x [0.01, 0.49] x [0.01, 0.24] placed by `body_attrs` (the mesh, with its OBJ vertices off the
// body's origin by `offset`) and the box primitive at the same place: the same voxels and cells, surface and solid.
void expect_mesh_box_equals_primitive(const std::string& body_attrs, const Eigen::Isometry3d& T_body) {
  const Eigen::Vector3d lo(0.01, 0.01, 0.01), hi(0.99, 0.49, 0.24), offset(1.3, -0.7, 0.2);
  MeshDir dir;
  dir.write("box.obj", box_obj(lo + offset, hi + offset));
  World world = World::from_string(mesh_world("box.obj", body_attrs), dir.path());
  const auto geoms = obstacle_geoms(world);
  ASSERT_EQ(geoms.size(), 1u);
  const ObstacleGeom& mesh = geoms[0];
  ASSERT_EQ(mesh.shape, ShapeType::mesh);
  EXPECT_TRUE(mesh.mesh->closed());
  EXPECT_TRUE(truth_notes(world).empty());
  Eigen::Isometry3d T_box = T_body;
  T_box.translation() = T_body * (0.5 * (lo + hi) + offset);
  const ObstacleGeom box = box_geom(0.5 * (hi - lo), T_box);
  for (const double s : {0.05, 0.1}) {
    for (const bool solid : {false, true}) {
      const auto from_mesh = voxels(mesh, s, solid), from_box = voxels(box, s, solid);
      EXPECT_FALSE(from_box.empty());
      EXPECT_EQ(from_mesh, from_box) << "voxel " << s << (solid ? " solid" : " surface");
    }
    const Eigen::AlignedBox3d b = box.aabb_W();
    const double z0 = b.min().z(), dz = b.sizes().z();
    EXPECT_FALSE(cells(box, s, z0 - 0.1, z0 + 0.3 * dz).empty());
    EXPECT_EQ(cells(mesh, s, z0 - 0.1, z0 + 0.3 * dz), cells(box, s, z0 - 0.1, z0 + 0.3 * dz)) << "cells " << s;
    EXPECT_EQ(cells(mesh, s, z0 + 0.45 * dz, z0 + 0.55 * dz), cells(box, s, z0 + 0.45 * dz, z0 + 0.55 * dz))
        << "cells in a band across the solid's middle, " << s;
  }
}

TEST(MeshTruth, CubeMeshEqualsTheBoxPrimitive) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(-1.3, 0.7, 1.0);  // the box lands at 0.01..0.99, 0.01..0.49, 1.21..1.44
  expect_mesh_box_equals_primitive("pos=\"-1.3 0.7 1.0\"", T);
}

TEST(MeshTruth, RotatedOffsetMeshEqualsTheBoxPrimitive) {
  // The body's world pose as MuJoCo computes it from euler (degrees, its default convention).
  MeshDir dir;
  dir.write("probe.obj", box_obj({0, 0, 0}, {0.1, 0.1, 0.1}));
  World probe = World::from_string(mesh_world("probe.obj", "pos=\"0.37 -0.21 0.9\" euler=\"17 0 29\""), dir.path());
  const int body = probe.body_id("room");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    T.translation()[r] = probe.data()->xpos[3 * body + r];
    for (int c = 0; c < 3; ++c) T.linear()(r, c) = probe.data()->xmat[9 * body + 3 * r + c];
  }
  expect_mesh_box_equals_primitive("pos=\"0.37 -0.21 0.9\" euler=\"17 0 29\"", T);
}

TEST(MeshTruth, OffCentreObjLandsWhereItsVerticesSay) {
  // MuJoCo 2.2.2 moves an OBJ's vertices to their centre of mass and principal axes and puts that offset into the
  // geom's pose; the triangles in the world must be the file's vertices placed by the body.
  MeshDir dir;
  dir.write("l.obj",
            "v 2 1 0\nv 2.6 1 0\nv 2.6 1.2 0\nv 2.2 1.2 0\nv 2.2 1.8 0\nv 2 1.8 0\n"
            "v 2 1 0.5\nv 2.6 1 0.5\nv 2.6 1.2 0.5\nv 2.2 1.2 0.5\nv 2.2 1.8 0.5\nv 2 1.8 0.5\n"
            "f 1 3 2\nf 1 4 3\nf 1 6 4\nf 6 5 4\n"        // bottom (an L), facing down
            "f 7 8 9\nf 7 9 10\nf 7 10 12\nf 12 10 11\n"  // top
            "f 1 2 8\nf 1 8 7\nf 2 3 9\nf 2 9 8\nf 3 4 10\nf 3 10 9\n"
            "f 4 5 11\nf 4 11 10\nf 5 6 12\nf 5 12 11\nf 6 1 7\nf 6 7 12\n");
  World world = World::from_string(mesh_world("l.obj", "pos=\"0.52 -0.23 0.1\""), dir.path());
  const auto geoms = obstacle_geoms(world);
  ASSERT_EQ(geoms.size(), 1u);
  const ObstacleGeom& g = geoms[0];
  EXPECT_TRUE(g.mesh->closed());
  EXPECT_EQ(g.mesh->faces().size(), 20u);
  const Eigen::AlignedBox3d box = g.aabb_W();
  EXPECT_NEAR(box.min().x(), 2.52, 1e-6);
  EXPECT_NEAR(box.max().x(), 3.12, 1e-6);
  EXPECT_NEAR(box.min().y(), 0.77, 1e-6);
  EXPECT_NEAR(box.max().y(), 1.57, 1e-6);
  EXPECT_NEAR(box.min().z(), 0.1, 1e-6);
  EXPECT_NEAR(box.max().z(), 0.6, 1e-6);
  for (const auto& v : g.mesh->vertices()) {  // every vertex is one of the file's, moved by the body
    const Eigen::Vector3d p = g.T_world_geom * v - Eigen::Vector3d(0.52, -0.23, 0.1);
    EXPECT_TRUE(std::abs(p.z()) < 1e-6 || std::abs(p.z() - 0.5) < 1e-6) << p.transpose();
    const bool x_known = std::abs(p.x() - 2) < 1e-6 || std::abs(p.x() - 2.2) < 1e-6 || std::abs(p.x() - 2.6) < 1e-6;
    const bool y_known = std::abs(p.y() - 1) < 1e-6 || std::abs(p.y() - 1.2) < 1e-6 || std::abs(p.y() - 1.8) < 1e-6;
    EXPECT_TRUE(x_known && y_known) << p.transpose();
  }
  // In the world the L's foot is x 2.52..3.12, y 0.77..0.97 and its leg x 2.52..2.72, y 0.97..1.57; the notch
  // between them, which the bounding box would fill, is empty.
  EXPECT_LT(g.signed_distance_m({2.62, 1.22, 0.35}), 0.0);   // in the leg
  EXPECT_GT(g.signed_distance_m({2.92, 1.32, 0.35}), 0.05);  // in the notch
  // Its footprint at 0.1 m is the L (foot: x cells 25..31, y 7..9; leg: x 25..27, y 10..15), not the 7 x 9 box.
  const auto footprint = cells(g, 0.1, 0.2, 0.4);
  EXPECT_EQ(footprint.size(), 7u * 3u + 3u * 6u);
}

TEST(MeshTruth, SingleTriangleHasTheHandComputedVoxels) {
  // In the plane y = 0.05, the triangle x >= 0.05, z >= 0.05, x + z <= 0.42. Voxel (i, 0, k) of 0.1 m meets it
  // when max(0.1 i, 0.05) + max(0.1 k, 0.05) <= 0.42: i = 0, 1: k 0..3; i = 2: k 0..2; i = 3: k 0..1.
  const ObstacleGeom g = mesh_geom({{0.05, 0.05, 0.05}, {0.37, 0.05, 0.05}, {0.05, 0.05, 0.37}}, {{0, 1, 2}});
  std::vector<VoxelKey> expected;
  for (int i = 0; i <= 3; ++i)
    for (int k = 0; k <= (i <= 1 ? 3 : i == 2 ? 2 : 1); ++k) expected.push_back({i, 0, k});
  EXPECT_EQ(voxels(g, 0.1, false), expected);
  EXPECT_EQ(voxels(g, 0.1, true), expected);  // open: the solid is the surface
  EXPECT_FALSE(g.mesh->closed());
  // Turned by 90 degrees about z (x -> y), the same voxels with x and y swapped and negated.
  const ObstacleGeom turned = mesh_geom({{0.05, 0.05, 0.05}, {0.37, 0.05, 0.05}, {0.05, 0.05, 0.37}}, {{0, 1, 2}},
                                        pose({0, 0, 0}, M_PI / 2, 0));
  std::vector<VoxelKey> swapped;
  for (const auto& k : expected) swapped.push_back({-1, k.x, k.z});
  std::sort(swapped.begin(), swapped.end());
  EXPECT_EQ(voxels(turned, 0.1, false), swapped);
}

TEST(MeshTruth, OpenMeshSolidFallsBackToTheSurfaceWithANote) {
  MeshDir dir;
  dir.write("open.obj", box_obj({0.01, 0.01, 0.01}, {0.49, 0.49, 0.39}, {5}));  // no top
  dir.write("closed.obj", box_obj({0.01, 0.01, 0.01}, {0.49, 0.49, 0.39}));
  World open = World::from_string(mesh_world("open.obj", ""), dir.path());
  World closed = World::from_string(mesh_world("closed.obj", ""), dir.path());
  const ObstacleGeom g_open = obstacle_geoms(open).at(0), g_closed = obstacle_geoms(closed).at(0);
  EXPECT_FALSE(g_open.mesh->closed());
  EXPECT_EQ(g_open.mesh->open_edges(), 4u);
  EXPECT_TRUE(g_closed.mesh->closed());
  EXPECT_EQ(voxels(g_open, 0.05, true), voxels(g_open, 0.05, false));
  EXPECT_GT(voxels(g_closed, 0.05, true).size(), voxels(g_closed, 0.05, false).size());
  // The surface is the closed box's without the top layer's inner voxels.
  EXPECT_LT(voxels(g_open, 0.05, false).size(), voxels(g_closed, 0.05, false).size());
  const auto notes = truth_notes(open);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].note.find("geom 'scan_geom' (mesh 'scan', body 'room')"), std::string::npos) << notes[0].note;
  EXPECT_NE(notes[0].note.find("not closed"), std::string::npos);
  EXPECT_TRUE(truth_notes(closed).empty());
  // Footprint above the bottom: the walls only (open) against the whole box (closed): 10 x 10 cells.
  EXPECT_EQ(cells(g_closed, 0.05, 0.1, 0.3).size(), 100u);
  EXPECT_EQ(cells(g_open, 0.05, 0.1, 0.3).size(), 36u);
}

TEST(MeshTruth, TetrahedronFootprintIsItsShadowInTheBand) {
  // x, y, z >= 0.01 and x + y + z <= 0.43; in the band z 0.05..0.3 a cell (i, j) of 0.1 m meets it when
  // max(0.1 i, 0.01) + max(0.1 j, 0.01) <= 0.38: 4 + 3 + 2 + 1 cells (its bounding box covers 5 x 5).
  MeshDir dir;
  dir.write("tet.obj",
            "v 0.01 0.01 0.01\nv 0.41 0.01 0.01\nv 0.01 0.41 0.01\nv 0.01 0.01 0.41\n"
            "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  World world = World::from_string(mesh_world("tet.obj", ""), dir.path());
  const ObstacleGeom g = obstacle_geoms(world).at(0);
  EXPECT_TRUE(g.mesh->closed());
  std::vector<CellKey> expected;
  for (int i = 0; i <= 3; ++i)
    for (int j = 0; j <= 3 - i; ++j) expected.push_back({i, j});
  EXPECT_EQ(cells(g, 0.1, 0.05, 0.3), expected);
  // The solid tests agree with the cells: a column outside the shadow misses, one inside meets.
  EXPECT_FALSE(
      g.intersects_solid(Eigen::AlignedBox3d(Eigen::Vector3d(0.3, 0.1, 0.05), Eigen::Vector3d(0.4, 0.2, 0.3)), 0.005));
  EXPECT_TRUE(
      g.intersects_solid(Eigen::AlignedBox3d(Eigen::Vector3d(0.2, 0.1, 0.05), Eigen::Vector3d(0.3, 0.2, 0.3)), 0.005));
  EXPECT_TRUE(g.contains_box(Eigen::AlignedBox3d(Eigen::Vector3d(0.05, 0.05, 0.05), Eigen::Vector3d(0.1, 0.1, 0.1))));
  EXPECT_NEAR(g.signed_distance_m({0.06, 0.06, 0.06}), -0.05, 1e-6);  // nearest: the three faces at 0.01
  EXPECT_NEAR(g.signed_distance_m({0.06, 0.06, -0.04}), 0.05, 1e-6);
}

// --- Height fields and planes -------------------------------------------------------------------------------

TEST(MeshTruth, FlatHeightFieldEqualsItsBox) {
  World world = World::from_string(kHeightFieldWorld);
  float* data = world.mutable_model()->hfield_data;
  for (int i = 0; i < 35; ++i) data[i] = 0.5f;  // the top 0.2 m above the geom (z 0.413), the base 0.11 m below
  world.forward();
  const ObstacleGeom g = obstacle_geoms(world).at(0);
  ASSERT_EQ(g.shape, ShapeType::mesh);
  EXPECT_TRUE(g.mesh->closed());
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.3, 0.2, 0.213 + 0.5 * (0.2 - 0.11));
  const ObstacleGeom box = box_geom({0.61, 0.43, 0.5 * (0.2 + 0.11)}, T);
  for (const bool solid : {false, true}) EXPECT_EQ(voxels(g, 0.05, solid), voxels(box, 0.05, solid));
  EXPECT_EQ(cells(g, 0.05, 0.15, 0.3), cells(box, 0.05, 0.15, 0.3));
}

TEST(MeshTruth, PlanesFloorLeftOutOthersExactOrNoted) {
  World world = World::from_string(R"(
<mujoco><worldbody>
  <geom name="floor" type="plane" size="5 5 0.1"/>
  <geom name="panel" type="plane" pos="1.03 0 0.52" zaxis="1 0 0" size="0.5 0.37 0.1"/>
  <geom name="endless" type="plane" pos="-2 0 0" zaxis="1 0 0" size="0 0 0.1"/>
</worldbody></mujoco>)");
  const auto geoms = obstacle_geoms(world);
  ASSERT_EQ(geoms.size(), 1u);  // the panel: the floor is left out, the infinite plane too
  EXPECT_EQ(geoms[0].shape, ShapeType::mesh);
  const auto v = voxels(geoms[0], 0.1, false);  // x layer 10, y -0.37..0.37 (8 voxels), z 0.02..1.02 (11)
  EXPECT_EQ(v.size(), 8u * 11u);
  const auto notes = truth_notes(world);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].note.find("'endless'"), std::string::npos) << notes[0].note;
}

// --- The shipped scan world ---------------------------------------------------------------------------------

TEST(MeshTruth, ShippedMeshRoomIsItsWallsAndTable) {
  World world = World::from_file(test::worlds_dir() + "/mesh_room.xml");
  const auto geoms = obstacle_geoms(world);
  ASSERT_EQ(geoms.size(), 2u);
  EXPECT_EQ(geoms[0].body_name, "walls");
  EXPECT_EQ(geoms[1].body_name, "table");
  for (const auto& g : geoms) EXPECT_TRUE(g.shape == ShapeType::mesh && g.mesh->closed()) << g.label;
  EXPECT_TRUE(truth_notes(world).empty());
  // The footprints are the rectangles worlds/mesh_room.xml describes (cells of 0.05 m meeting one), not the boxes.
  struct Rect {
    double x0, x1, y0, y1;
  };
  const std::vector<Rect> walls = {{-1.113, 5.087, 1.522, 1.622},
                                   {-1.113, 1.587, -1.578, -1.478},
                                   {2.487, 5.087, -1.578, -1.478},
                                   {-1.113, -1.013, -1.478, 1.522},
                                   {4.987, 5.087, -1.478, 1.522}};
  const std::vector<Rect> table = {{2.213, 3.213, 0.587, 1.187}};
  auto cells_of = [](const std::vector<Rect>& rects) {
    std::vector<CellKey> out;
    for (int x = -40; x <= 110; ++x)
      for (int y = -40; y <= 40; ++y)
        for (const Rect& r : rects)
          if (x * 0.05 <= r.x1 && (x + 1) * 0.05 >= r.x0 && y * 0.05 <= r.y1 && (y + 1) * 0.05 >= r.y0) {
            out.push_back({x, y});
            break;
          }
    return out;
  };
  const auto prints = footprints(geoms, 0.05, 0.1, 2.0);
  EXPECT_EQ(prints[0].cells, cells_of(walls));
  EXPECT_EQ(prints[1].cells, cells_of(table));
  // mj_ray meets the same triangles: through the door gap nothing, beside it the south wall.
  EXPECT_FALSE(cast_ray(world, {2.0, 0.0, 0.5}, {0, -1, 0}).hit);
  EXPECT_NEAR(cast_ray(world, {1.0, 0.0, 0.5}, {0, -1, 0}).distance_m, 1.478, 1e-5);
  EXPECT_NEAR(cast_ray(world, {2.0, 0.0, 0.5}, {0, 1, 0}).distance_m, 1.522, 1e-5);
}

// --- Bad input ----------------------------------------------------------------------------------------------

TEST(MeshTruth, BadMeshesAreRefusedNamingTheGeom) {
  EXPECT_THROW(TriangleMesh({{0, 0, 0}}, {}, "no faces"), std::invalid_argument);
  try {
    TriangleMesh({{0, 0, 0}, {1, 0, 0}, {0, std::nan(""), 0}}, {{0, 1, 2}}, "geom 'bad'");
    ADD_FAILURE() << "a NaN vertex was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("geom 'bad': vertex 2 is not finite"), std::string::npos) << e.what();
  }
  EXPECT_THROW(TriangleMesh({{0, 0, 0}}, {{0, 1, 2}}, "index"), std::invalid_argument);

  // A mesh spanning 2 km at 0.02 m: refused at once, before its voxels are allocated.
  MeshDir dir;
  dir.write("huge.obj", box_obj({-1000, -1000, 0}, {1000, 1000, 2}));
  World world = World::from_string(mesh_world("huge.obj", ""), dir.path());
  const ObstacleGeom g = obstacle_geoms(world).at(0);
  const auto start = std::chrono::steady_clock::now();
  try {
    voxels(g, 0.02, false);
    ADD_FAILURE() << "a 2 km mesh was voxelized at 0.02 m";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("geom 'scan_geom'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("candidate voxels"), std::string::npos) << e.what();
  }
  EXPECT_THROW(footprints({g}, 1e-5, 0.0, 1.0), std::invalid_argument);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
}

TEST(MeshTruth, MissingMeshFileIsMujocosErrorWithTheName) {
  MeshDir dir;
  try {
    World::from_string(mesh_world("no_such_scan.obj", ""), dir.path());
    ADD_FAILURE() << "a missing mesh file loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_scan.obj"), std::string::npos) << e.what();
  }
}

// --- Cost ---------------------------------------------------------------------------------------------------

TEST(MeshTruth, HundredThousandTrianglesAtFiveCentimetres) {
  // A closed bumpy sphere of radius 2.5 m with 100k triangles: per-triangle candidates keep it near linear. The
  // bound only catches a return to every voxel against every triangle (hours); the figure goes to the header.
  std::mt19937 rng(1);
  const auto built = std::chrono::steady_clock::now();
  const ObstacleGeom g = bumpy_sphere(rng, 200, 253, 2.5, 0.02, pose({0.013, 0.021, 2.6}, 0.3, 0.2));
  std::printf("mesh built (closure, hierarchy) in %.3f s\n",
              std::chrono::duration<double>(std::chrono::steady_clock::now() - built).count());
  ASSERT_GE(g.mesh->faces().size(), 100000u);
  for (const bool solid : {false, true}) {
    const auto start = std::chrono::steady_clock::now();
    const auto v = voxels(g, 0.05, solid);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("%zu triangles, %s at 0.05 m: %zu voxels in %.3f s\n", g.mesh->faces().size(),
                solid ? "solid" : "surface", v.size(), s);
    EXPECT_LT(s, 60.0);
    const double sphere_voxels = solid ? 4.0 / 3 * M_PI * std::pow(2.5 / 0.05, 3) : 4 * M_PI * std::pow(2.5 / 0.05, 2);
    EXPECT_GT(v.size(), (solid ? 0.9 : 1.5) * sphere_voxels);
    EXPECT_LT(v.size(), (solid ? 1.2 : 4.0) * sphere_voxels);
  }
  const auto start = std::chrono::steady_clock::now();
  const auto c = cells(g, 0.05, 0.1, 2.0);
  std::printf("footprint in z 0.1..2.0 m: %zu cells in %.3f s\n", c.size(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

}  // namespace
}  // namespace stvl::truth
#pragma once
// Helpers of the mesh truth tests (test_mesh_truth.cpp, test_mesh_truth_reference.cpp): mesh files in a fresh
// folder; boxes, meshes and bumpy spheres as obstacle geoms; their voxels and cells; poses; a small height field.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "truth/ground_truth.hpp"

namespace stvl::truth::mesh_test {

// A fresh folder for mesh files, removed with the object.
class MeshDir {
 public:
  MeshDir() {
    static int serial = 0;
    dir_ = std::filesystem::temp_directory_path() /
           ("stvl_mesh_" + std::to_string(::getpid()) + "_" + std::to_string(serial++));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  ~MeshDir() {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }
  std::string path() const { return dir_.string(); }
  void write(const std::string& name, const std::string& text) const { std::ofstream(dir_ / name) << text; }

 private:
  std::filesystem::path dir_;
};

// OBJ text of the box [lo, hi] (12 triangles, outward), without the faces listed in `skip` (0..5: -x +x -y +y -z +z).
inline std::string box_obj(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, std::vector<int> skip = {}) {
  std::string obj;
  char line[160];
  for (int i = 0; i < 8; ++i) {
    std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(),
                  i & 4 ? hi.z() : lo.z());
    obj += line;
  }
  // OBJ indices from 1; vertex i+1 has bits x=1, y=2, z=4.
  const int quads[6][4] = {{1, 5, 7, 3}, {2, 4, 8, 6}, {1, 2, 6, 5}, {3, 7, 8, 4}, {1, 3, 4, 2}, {5, 6, 8, 7}};
  for (int f = 0; f < 6; ++f) {
    if (std::find(skip.begin(), skip.end(), f) != skip.end()) continue;
    const auto& q = quads[f];
    std::snprintf(line, sizeof line, "f %d %d %d\nf %d %d %d\n", q[0], q[1], q[2], q[0], q[2], q[3]);
    obj += line;
  }
  return obj;
}

inline std::string mesh_world(const std::string& file, const std::string& body_attrs, const std::string& extra = "") {
  return "<mujoco><asset><mesh name=\"scan\" file=\"" + file + "\"/></asset><worldbody><body name=\"room\" " +
         body_attrs + "><geom name=\"scan_geom\" type=\"mesh\" mesh=\"scan\"/></body>" + extra +
         "</worldbody></mujoco>";
}

inline ObstacleGeom box_geom(const Eigen::Vector3d& half, const Eigen::Isometry3d& T) {
  ObstacleGeom g;
  g.shape = ShapeType::box;
  g.size_m = half;
  g.T_world_geom = T;
  g.body_name = "box";
  return g;
}

inline ObstacleGeom mesh_geom(std::vector<Eigen::Vector3d> vertices, std::vector<TriangleMesh::Face> faces,
                              const Eigen::Isometry3d& T = Eigen::Isometry3d::Identity()) {
  ObstacleGeom g;
  g.shape = ShapeType::mesh;
  g.mesh = std::make_shared<const TriangleMesh>(std::move(vertices), std::move(faces), "test mesh");
  g.size_m = 0.5 * g.mesh->aabb_G().sizes();
  g.T_world_geom = T;
  g.body_name = "mesh";
  g.label = "test mesh";
  return g;
}

inline std::vector<VoxelKey> voxels(const ObstacleGeom& g, double s, bool solid) {
  VoxelizeOptions options;
  options.voxel_size_m = s;
  options.solid = solid;
  return voxelize(g, options);
}

inline std::vector<CellKey> cells(const ObstacleGeom& g, double s, double z0, double z1) {
  return footprints({g}, s, z0, z1).at(0).cells;
}

inline Eigen::Isometry3d pose(const Eigen::Vector3d& t, double yaw, double roll) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = t;
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  return T;
}

// A closed, non-convex bumpy sphere: a UV sphere of radius r with every vertex's radius scaled by 1 +- bump.
inline ObstacleGeom bumpy_sphere(std::mt19937& rng, int rings, int segments, double r, double bump,
                                 const Eigen::Isometry3d& T) {
  std::uniform_real_distribution<double> u(1 - bump, 1 + bump);
  std::vector<Eigen::Vector3d> v;
  v.push_back({0, 0, r * u(rng)});
  for (int i = 1; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const double theta = M_PI * i / rings, phi = 2 * M_PI * j / segments, k = r * u(rng);
      v.push_back({k * std::sin(theta) * std::cos(phi), k * std::sin(theta) * std::sin(phi), k * std::cos(theta)});
    }
  v.push_back({0, 0, -r * u(rng)});
  const int south = static_cast<int>(v.size()) - 1;
  auto at = [&](int i, int j) { return 1 + (i - 1) * segments + (j % segments); };
  std::vector<TriangleMesh::Face> f;
  for (int j = 0; j < segments; ++j) {
    f.push_back({0, at(1, j), at(1, j + 1)});
    f.push_back({south, at(rings - 1, j + 1), at(rings - 1, j)});
    for (int i = 1; i + 1 < rings; ++i) {
      f.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      f.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  return mesh_geom(std::move(v), std::move(f), T);
}

inline constexpr const char* kHeightFieldWorld = R"(
<mujoco>
  <asset><hfield name="terrain" nrow="5" ncol="7" size="0.61 0.43 0.4 0.11"/></asset>
  <worldbody><body name="ground" pos="0.3 0.2 0.213"><geom name="bumps" type="hfield" hfield="terrain"/></body></worldbody>
</mujoco>)";

}  // namespace stvl::truth::mesh_test

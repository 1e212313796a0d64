#pragma once
// Ground-truth geometry from the simulated world, independent of rendering: obstacle geoms,
// exact voxelization, 2D footprints, ray casting. Poses are read from data() as of the last
// World::step()/forward(), so moved mocap bodies are seen where they are now.
//
// Voxelization is a region-vs-shape test, not sampling. A voxel is a closed cube.
//  - solid: the cube meets the shape's solid. Exact (separating axes) for boxes and spheres.
//    Capsules, cylinders, ellipsoids: the cube is split along its longest axis until the
//    shape's signed distance at a piece's centre decides it (inside: hit; farther than the
//    piece's half diagonal: miss); pieces still undecided when their half diagonal drops below
//    tolerance_fraction * voxel_size_m count as hits. So the result is conservative: it holds
//    every exact voxel and at most a few extra ones within that tolerance of the shape. The
//    ellipsoid uses a lower bound of the distance, min_radius * (|p / radii| - 1).
//  - surface: the cube meets the solid and not all 8 corners are inside (exact for convex shapes).
//  - meshes are represented by their oriented bounding box (ObstacleGeom::approximated = true);
//    planes and height fields are skipped.
// Cost: one test per voxel of each geom's bounding box (clipped to bounds_W), single-threaded.
// The whole office corridor, z 0..2 m: 0.16 s at 0.05 m; 1.0 s at 0.02 m (1.36 M surface voxels).
// Clip with bounds_W (a height band, the camera's reach) when calling it often.
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "common/voxel_key.hpp"
#include "sim/world.hpp"

namespace stvl::sim {

// Geom groups as a bit mask (bit g = group g). Obstacles live in groups 0 and 1; the robot in 2.
constexpr unsigned kObstacleGroups = 0b011;

enum class ShapeType { box, sphere, capsule, cylinder, ellipsoid };

struct ObstacleGeom {
  int geom_id = -1;
  int body_id = -1;
  std::string body_name;
  ShapeType shape = ShapeType::box;
  Eigen::Isometry3d T_world_geom = Eigen::Isometry3d::Identity();
  // Half sizes in the geom frame: box (hx, hy, hz); sphere (r, -, -); capsule and cylinder
  // (r, half_length along z, -); ellipsoid (rx, ry, rz).
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();
  bool approximated = false;  // a mesh replaced by its oriented bounding box

  Eigen::AlignedBox3d aabb_W() const;
  // Signed distance (negative inside); exact except for ellipsoids (a same-sign lower bound).
  double signed_distance_m(const Eigen::Vector3d& p_W) const;
  // Closed axis-aligned box vs the solid shape, conservative within tolerance_m (see above).
  bool intersects_solid(const Eigen::AlignedBox3d& box_W, double tolerance_m) const;
  bool contains_box(const Eigen::AlignedBox3d& box_W) const;  // all 8 corners inside
};

// Geoms whose group is in group_mask, excluding planes and height fields, with current poses.
std::vector<ObstacleGeom> obstacle_geoms(const World& world, unsigned group_mask = kObstacleGroups);

struct VoxelizeOptions {
  double voxel_size_m = 0.05;
  bool solid = false;  // false: surface voxels; true: every voxel meeting the solid
  // Only voxels meeting this box are produced; default: everywhere.
  Eigen::AlignedBox3d bounds_W = Eigen::AlignedBox3d(Eigen::Vector3d::Constant(-1e6), Eigen::Vector3d::Constant(1e6));
  double tolerance_fraction = 0.05;
};

struct BodyVoxels {
  int body_id = -1;
  std::string body_name;
  std::vector<VoxelKey> voxels;  // sorted, unique
};

// Throws std::invalid_argument on voxel_size_m <= 0, empty bounds or more than 2^31 candidates.
std::vector<VoxelKey> voxelize(const ObstacleGeom& geom, const VoxelizeOptions& options);
// Geoms merged per body, in order of first appearance.
std::vector<BodyVoxels> voxelize_bodies(const std::vector<ObstacleGeom>& geoms, const VoxelizeOptions& options);
VoxelSet merge(const std::vector<BodyVoxels>& bodies);

struct BodyFootprint {
  int body_id = -1;
  std::string body_name;
  std::vector<CellKey> cells;  // sorted, unique; cell index = floor(p / cell_size_m)
};

// Cells whose column [min_z_m, max_z_m] meets a body's solid (same test and tolerance as above).
std::vector<BodyFootprint> footprints(const std::vector<ObstacleGeom>& geoms, double cell_size_m, double min_z_m,
                                      double max_z_m, double tolerance_fraction = 0.05);

struct RayHit {
  bool hit = false;
  double distance_m = std::numeric_limits<double>::infinity();
  int geom_id = -1;
  int body_id = -1;
  std::string body_name;
};

// mj_ray against geoms in group_mask (static ones included), skipping exclude_body_id (-1: none).
// Hits beyond max_range_m are reported as misses. Throws on a zero or non-finite direction.
RayHit cast_ray(const World& world, const Eigen::Vector3d& origin_W, const Eigen::Vector3d& direction_W,
                double max_range_m = std::numeric_limits<double>::infinity(),
                unsigned group_mask = kObstacleGroups, int exclude_body_id = -1);

}  // namespace stvl::sim

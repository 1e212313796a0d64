#pragma once
// Ground-truth geometry from the simulated world, read from the model rather than from rendered
// images (but as the renderer draws it): obstacle geoms, exact voxelization, 2D footprints, ray
// casting (mj_ray, which meets meshes' triangles). Poses are read from data() as of the last
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
//  - meshes and height fields are their triangles, as the renderer draws them (MuJoCo 2.2.2
//    renders mesh_face, not the convex hull its collisions use): ShapeType::mesh, exact.
//    Surface: the cube meets a triangle (separating axes). Solid, for a closed mesh (every
//    edge shared by an even number of faces once vertices at equal positions are merged): the
//    surface voxels and those whose centre is inside (parity of crossings on a vertical line;
//    truth/mesh_voxelize.hpp). An open mesh's solid is its surface: truth_notes() says so. A
//    height field is closed: its grid (split as the renderer splits it), four sides and a base.
//    Candidates per triangle only (its columns, its heights in each), never every voxel
//    against every triangle; truth/reference/ holds the brute-force twin the tests compare.
//  - planes: a horizontal plane at or below z = 0.01 m is the floor and is left out on purpose
//    (the marking band excludes it); other finite planes are their rectangle (a surface); an
//    infinite one that is not the floor is left out, and truth_notes() says so. Geoms named floor*
//    (a ramp, a raised floor: drivable ground) are left out like the floor.
// Cost (primitives): one test per voxel of each geom's bounding box (clipped to bounds_W), single-threaded.
// The whole office corridor, z 0..2 m: 0.16 s at 0.05 m; 1.0 s at 0.02 m (1.36 M surface voxels).
// Meshes: per triangle. A closed 100k-triangle mesh (a bumpy sphere of radius 2.5 m, test
// MeshTruth.HundredThousandTrianglesAtFiveCentimetres) at 0.05 m: surface 0.18 s (66.5k voxels),
// solid 0.27 s (557k voxels), footprint 0.04 s; its closure and hierarchy, built once per
// distinct mesh, 0.2 s (this 2-core machine, up to twice that when loaded). Every voxel
// against every triangle (truth/reference/) would be some 10^11 tests.
// Clip with bounds_W (a height band, the camera's reach) when calling it often.
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "common/voxel_key.hpp"
#include "sim/world.hpp"
#include "truth/triangle_mesh.hpp"

namespace stvl::truth {

// Geom groups as a bit mask (bit g = group g). Obstacles live in groups 0 and 1; the robot in 2.
constexpr unsigned kObstacleGroups = 0b011;

enum class ShapeType { box, sphere, capsule, cylinder, ellipsoid, mesh };

struct ObstacleGeom {
  int geom_id = -1;
  int body_id = -1;
  std::string body_name;
  ShapeType shape = ShapeType::box;
  Eigen::Isometry3d T_world_geom = Eigen::Isometry3d::Identity();
  // Half sizes in the geom frame: box (hx, hy, hz); sphere (r, -, -); capsule and cylinder
  // (r, half_length along z, -); ellipsoid (rx, ry, rz); mesh: half the extent of its triangles.
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();
  // ShapeType::mesh: the triangles in the geom frame (a mesh asset, a height field or a finite
  // plane), shared by every copy and by geoms with identical data.
  std::shared_ptr<const TriangleMesh> mesh;
  std::string label;  // "geom 'name' (mesh 'scan', body 'room')", for messages

  Eigen::AlignedBox3d aabb_W() const;  // meshes: of their vertices (tight), O(vertices)
  // Signed distance (negative inside); exact except for ellipsoids (a same-sign lower bound).
  // Meshes: the distance to the nearest triangle, negative inside a closed mesh.
  double signed_distance_m(const Eigen::Vector3d& p_W) const;
  // Closed axis-aligned box vs the solid shape, conservative within tolerance_m (see above);
  // meshes: exact (a triangle meets the box, or its centre is inside a closed mesh).
  bool intersects_solid(const Eigen::AlignedBox3d& box_W, double tolerance_m) const;
  // All 8 corners inside; meshes: inside a closed mesh and meeting no triangle.
  bool contains_box(const Eigen::AlignedBox3d& box_W) const;
};

// Geoms whose group is in group_mask, with current poses: boxes, spheres, capsules, cylinders,
// ellipsoids, meshes, height fields and finite planes; the floor and infinite planes are left
// out. Throws std::invalid_argument naming the geom for a mesh without faces or with a
// non-finite vertex.
std::vector<ObstacleGeom> obstacle_geoms(const sim::World& world, unsigned group_mask = kObstacleGroups);

// Sets each geom's T_world_geom to its pose in world now, as obstacle_geoms() would (the rest is kept). Throws
// std::invalid_argument for a geom id outside the model.
void refresh_poses(const sim::World& world, std::vector<ObstacleGeom>& geoms);
// Whether which geoms obstacle_geoms() returns can change with the state: a plane on a moving body (mocap or
// jointed) is left out only while it lies as a floor. False: refresh_poses() keeps a list current.
bool poses_decide_membership(const sim::World& world, unsigned group_mask = kObstacleGroups);

// What the truth cannot make exact, one line per geom: an open mesh (its solid is its surface:
// solid voxels, footprints), an infinite plane that is not the floor (left out). Empty for
// every shipped world. Throws as obstacle_geoms() does.
struct TruthNote {
  int geom_id = -1;
  std::string geom;  // ObstacleGeom::label
  std::string note;  // one line naming the geom
};
std::vector<TruthNote> truth_notes(const sim::World& world, unsigned group_mask = kObstacleGroups);

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

// Throws std::invalid_argument on voxel_size_m <= 0, empty bounds or more than 2^31 candidates
// (meshes: voxels in their triangles' bounding boxes, counted before anything is allocated).
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
RayHit cast_ray(const sim::World& world, const Eigen::Vector3d& origin_W, const Eigen::Vector3d& direction_W,
                double max_range_m = std::numeric_limits<double>::infinity(), unsigned group_mask = kObstacleGroups,
                int exclude_body_id = -1);

}  // namespace stvl::truth

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <ostream>
#include <stdexcept>
#include <vector>

#include "tests/support/fixture.hpp"
#include "truth/ground_truth.hpp"

namespace stvl::truth {
namespace {

using sim::World;

// Dense surface samples (spacing voxel/20) land in voxels that the exact test must all report.
// The exact set may add voxels that the surface only grazes between samples: each must touch a
// sampled voxel, must hold a point within kGridFraction * voxel of the surface on a dense grid
// inside its cube, and together they stay below kMaxExtraFraction of the set.
constexpr double kSampleFraction = 0.05;
constexpr double kMaxExtraFraction = 0.06;
constexpr int kGrid = 11;
constexpr double kGridFraction = 0.5 * 1.7321 / (kGrid - 1) + 0.05;  // grid half-diagonal + tolerance

using Sampler = std::function<void(double spacing, const std::function<void(const Eigen::Vector3d&)>&)>;

ObstacleGeom make_geom(ShapeType shape, const Eigen::Vector3d& size, const Eigen::Isometry3d& T) {
  ObstacleGeom g;
  g.shape = shape;
  g.size_m = size;
  g.T_world_geom = T;
  g.body_name = "test";
  return g;
}

Eigen::Isometry3d test_pose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.0137, -0.2311, 0.4121);
  T.linear() = (Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  return T;
}

void sample_disk_grid(double r, double z, double spacing, const std::function<void(const Eigen::Vector3d&)>& emit) {
  for (double x = -r; x <= r; x += spacing)
    for (double y = -r; y <= r; y += spacing)
      if (x * x + y * y <= r * r) emit({x, y, z});
}

void sample_sphere_part(double r, double z_offset, int hemisphere, double spacing,
                        const std::function<void(const Eigen::Vector3d&)>& emit) {
  const int n_lat = static_cast<int>(std::ceil(M_PI * r / spacing)) + 1;
  for (int i = 0; i <= n_lat; ++i) {
    const double theta = M_PI * i / n_lat;
    const double z = r * std::cos(theta);
    if (hemisphere * z < 0) continue;
    const double ring = r * std::sin(theta);
    const int n_lon = std::max(1, static_cast<int>(std::ceil(2 * M_PI * ring / spacing)));
    for (int j = 0; j < n_lon; ++j) {
      const double phi = 2 * M_PI * j / n_lon;
      emit({ring * std::cos(phi), ring * std::sin(phi), z + z_offset});
    }
  }
}

void sample_tube(double r, double h, double spacing, const std::function<void(const Eigen::Vector3d&)>& emit) {
  const int n_lon = static_cast<int>(std::ceil(2 * M_PI * r / spacing));
  for (double z = -h; z <= h + 1e-12; z += spacing)
    for (int j = 0; j < n_lon; ++j) emit({r * std::cos(2 * M_PI * j / n_lon), r * std::sin(2 * M_PI * j / n_lon), z});
}

Sampler surface_sampler(const ObstacleGeom& g) {
  const Eigen::Vector3d s = g.size_m;
  switch (g.shape) {
    case ShapeType::box:
      return [s](double d, const auto& emit) {
        for (int axis = 0; axis < 3; ++axis) {
          const int u = (axis + 1) % 3, v = (axis + 2) % 3;
          for (double a = -s[u]; a <= s[u] + 1e-12; a += d)
            for (double b = -s[v]; b <= s[v] + 1e-12; b += d)
              for (double side : {-1.0, 1.0}) {
                Eigen::Vector3d p;
                p[axis] = side * s[axis];
                p[u] = a;
                p[v] = b;
                emit(p);
              }
        }
      };
    case ShapeType::sphere: return [s](double d, const auto& emit) { sample_sphere_part(s.x(), 0.0, 0, d, emit); };
    case ShapeType::cylinder:
      return [s](double d, const auto& emit) {
        sample_tube(s.x(), s.y(), d, emit);
        sample_disk_grid(s.x(), s.y(), d, emit);
        sample_disk_grid(s.x(), -s.y(), d, emit);
      };
    case ShapeType::capsule:
      return [s](double d, const auto& emit) {
        sample_tube(s.x(), s.y(), d, emit);
        sample_sphere_part(s.x(), s.y(), 1, d, emit);
        sample_sphere_part(s.x(), -s.y(), -1, d, emit);
      };
    case ShapeType::ellipsoid:
      return [s](double d, const auto& emit) {
        sample_sphere_part(1.0, 0.0, 0, d / s.maxCoeff(), [&](const Eigen::Vector3d& p) { emit(p.cwiseProduct(s)); });
      };
    case ShapeType::mesh:  // tests/sim/test_mesh_truth.cpp
      break;
  }
  return {};
}

struct Comparison {
  std::size_t exact = 0, sampled = 0, missing = 0, extra = 0, extra_far = 0, extra_unjustified = 0;
};

Comparison compare_surface(const ObstacleGeom& g, double voxel_size_m) {
  VoxelizeOptions options;
  options.voxel_size_m = voxel_size_m;
  const auto voxels = voxelize(g, options);
  const VoxelSet exact(voxels.begin(), voxels.end());
  VoxelSet sampled;
  surface_sampler(g)(kSampleFraction * voxel_size_m, [&](const Eigen::Vector3d& p_G) {
    sampled.insert(voxel_key(g.T_world_geom * p_G, voxel_size_m));
  });
  Comparison c{exact.size(), sampled.size(), 0, 0, 0, 0};
  for (const auto& k : sampled) c.missing += exact.count(k) ? 0 : 1;
  for (const auto& k : exact) {
    if (sampled.count(k)) continue;
    ++c.extra;
    bool near = false;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) near = near || sampled.count({k.x + dx, k.y + dy, k.z + dz});
    c.extra_far += near ? 0 : 1;
    double min_abs_sd = 1e9;
    const Eigen::Vector3d lo = voxel_center(k, voxel_size_m) - Eigen::Vector3d::Constant(0.5 * voxel_size_m);
    for (int i = 0; i < kGrid; ++i)
      for (int j = 0; j < kGrid; ++j)
        for (int l = 0; l < kGrid; ++l) {
          const Eigen::Vector3d p = lo + Eigen::Vector3d(i, j, l) * (voxel_size_m / (kGrid - 1));
          min_abs_sd = std::min(min_abs_sd, std::abs(g.signed_distance_m(p)));
        }
    c.extra_unjustified += min_abs_sd <= kGridFraction * voxel_size_m ? 0 : 1;
  }
  return c;
}

struct ShapeCase {
  const char* name;
  ShapeType shape;
  Eigen::Vector3d size;
  double volume_m3;
  double area_m2;
};

void PrintTo(const ShapeCase& c, std::ostream* os) { *os << c.name; }

class VoxelizeShape : public ::testing::TestWithParam<std::tuple<ShapeCase, double>> {};

TEST_P(VoxelizeShape, SurfaceMatchesDenseSampling) {
  const auto& [shape, voxel_size] = GetParam();
  const Comparison c = compare_surface(make_geom(shape.shape, shape.size, test_pose()), voxel_size);
  EXPECT_GT(c.exact, 10u);
  EXPECT_EQ(c.missing, 0u) << "sampled voxels the exact test rejected";
  EXPECT_EQ(c.extra_far, 0u);
  EXPECT_EQ(c.extra_unjustified, 0u);
  EXPECT_LE(static_cast<double>(c.extra), kMaxExtraFraction * c.exact) << "extra " << c.extra << " of " << c.exact;
}

TEST_P(VoxelizeShape, SolidCountBracketsVolume) {
  const auto& [shape, s] = GetParam();
  const ObstacleGeom g = make_geom(shape.shape, shape.size, test_pose());
  VoxelizeOptions options;
  options.voxel_size_m = s;
  options.solid = true;
  const double solid_m3 = voxelize(g, options).size() * s * s * s;
  options.solid = false;
  const double surface_m3 = voxelize(g, options).size() * s * s * s;
  // Solid voxels cover the shape; without the surface layer they lie inside it; and every solid
  // voxel is within a voxel diagonal of the shape (Steiner bound, first order).
  EXPECT_GE(solid_m3, shape.volume_m3);
  EXPECT_LE(solid_m3 - surface_m3, shape.volume_m3);
  EXPECT_LE(solid_m3, shape.volume_m3 + 1.2 * shape.area_m2 * s * std::sqrt(3.0));
}

// voxelize() skips contains_box() for cubes whose centre is outside (every primitive is convex): the same voxels
// as the plain per-cube test, contains_box() asked of every candidate, and never a contained cube with its centre
// outside.
TEST_P(VoxelizeShape, SurfaceIsThePlainPerCubeTest) {
  const auto& [shape, s] = GetParam();
  const ObstacleGeom g = make_geom(shape.shape, shape.size, test_pose());
  VoxelizeOptions options;
  options.voxel_size_m = s;
  const double half_diagonal = 0.5 * std::sqrt(3.0) * s, tolerance = options.tolerance_fraction * s;
  const Eigen::AlignedBox3d box = g.aabb_W();
  std::vector<VoxelKey> plain;
  std::size_t outside_centres = 0;
  for (int x = int(std::floor(box.min().x() / s)); x <= int(std::floor(box.max().x() / s)); ++x)
    for (int y = int(std::floor(box.min().y() / s)); y <= int(std::floor(box.max().y() / s)); ++y)
      for (int z = int(std::floor(box.min().z() / s)); z <= int(std::floor(box.max().z() / s)); ++z) {
        const Eigen::Vector3d lo(x * s, y * s, z * s);
        const Eigen::AlignedBox3d cube(lo, lo + Eigen::Vector3d::Constant(s));
        const double d = g.signed_distance_m(cube.center());
        if (d > 0.0 && d <= half_diagonal) {
          ++outside_centres;
          ASSERT_FALSE(g.contains_box(cube)) << x << " " << y << " " << z;
        }
        if (std::abs(d) <= half_diagonal && g.intersects_solid(cube, tolerance) && !g.contains_box(cube))
          plain.push_back({x, y, z});
      }
  EXPECT_GT(outside_centres, 10u);
  EXPECT_EQ(voxelize(g, options), plain);
}

const ShapeCase kShapes[] = {
    {"box", ShapeType::box, {0.3, 0.2, 0.45}, 8 * 0.3 * 0.2 * 0.45, 8 * (0.3 * 0.2 + 0.2 * 0.45 + 0.3 * 0.45)},
    {"sphere", ShapeType::sphere, {0.35, 0, 0}, 4.0 / 3 * M_PI* std::pow(0.35, 3), 4 * M_PI * 0.35 * 0.35},
    {"cylinder", ShapeType::cylinder, {0.2, 0.4, 0}, M_PI * 0.04 * 0.8, 2 * M_PI * 0.2 * 0.8 + 2 * M_PI * 0.04},
    {"capsule",
     ShapeType::capsule,
     {0.15, 0.5, 0},
     M_PI * 0.0225 * 1.0 + 4.0 / 3 * M_PI* std::pow(0.15, 3),
     2 * M_PI * 0.15 * 1.0 + 4 * M_PI * 0.0225},
    {"ellipsoid", ShapeType::ellipsoid, {0.4, 0.25, 0.15}, 4.0 / 3 * M_PI * 0.4 * 0.25 * 0.15, 4 * M_PI * 0.07},
};

INSTANTIATE_TEST_SUITE_P(Shapes, VoxelizeShape,
                         ::testing::Combine(::testing::ValuesIn(kShapes), ::testing::Values(0.05, 0.1, 0.0371)),
                         [](const auto& info) {
                           return std::string(std::get<0>(info.param).name) + "_" +
                                  std::to_string(static_cast<int>(std::get<1>(info.param) * 1e4));
                         });

TEST(Voxelize, AxisAlignedBoxHasExactCounts) {
  ObstacleGeom g;  // [0.0, 1.0) x [0.0, 0.5) x [0.0, 0.25) in 0.05 voxels, faces off the grid
  g.shape = ShapeType::box;
  g.size_m = {0.49, 0.24, 0.115};
  g.T_world_geom.translation() = Eigen::Vector3d(0.5, 0.25, 0.125);
  VoxelizeOptions options;
  options.voxel_size_m = 0.05;
  options.solid = false;
  EXPECT_EQ(voxelize(g, options).size(), 20u * 10u * 5u - 18u * 8u * 3u);
  options.solid = true;
  EXPECT_EQ(voxelize(g, options).size(), 20u * 10u * 5u);
  options.bounds_W = Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, 0.0), Eigen::Vector3d(2, 2, 0.07));
  EXPECT_EQ(voxelize(g, options).size(), 20u * 10u * 2u);  // layers z = 0 and 1
}

TEST(Voxelize, RejectsBadParameters) {
  ObstacleGeom g;
  g.size_m = {0.1, 0.1, 0.1};
  VoxelizeOptions options;
  options.voxel_size_m = 0.0;
  EXPECT_THROW(voxelize(g, options), std::invalid_argument);
  options.voxel_size_m = 1e-7;
  EXPECT_THROW(voxelize(g, options), std::invalid_argument);  // too many candidates
  EXPECT_THROW(footprints({g}, 0.05, 1.0, 0.5), std::invalid_argument);
}

const char* kTwoObstacles = R"(
<mujoco>
  <compiler autolimits="true"/>
  <include file="robot.xml"/>
  <worldbody>
    <geom name="floor" type="plane" size="10 10 0.1"/>
    <body name="crate" pos="3 0 0.2"><geom type="box" size="0.19 0.29 0.2"/></body>
    <body name="pole" pos="0 2 1.0"><geom type="cylinder" size="0.05 1.0" group="1"/></body>
    <body name="lamp" pos="0 -2 2.2"><geom type="sphere" size="0.1" group="3"/></body>
  </worldbody>
</mujoco>)";

TEST(GroundTruth, EnumeratesObstaclesOnly) {
  World world = World::from_string(kTwoObstacles, test::worlds_dir());
  const auto geoms = obstacle_geoms(world);
  ASSERT_EQ(geoms.size(), 2u);
  EXPECT_EQ(geoms[0].body_name, "crate");
  EXPECT_EQ(geoms[1].body_name, "pole");
  EXPECT_EQ(geoms[1].shape, ShapeType::cylinder);
  EXPECT_EQ(obstacle_geoms(world, 0b1000).size(), 1u);
}

// Drivable ground (geoms named floor*: a ramp, a raised floor) is left out like the floor plane; a geom merely
// containing "floor" in its name is not.
TEST(GroundTruth, GeomsNamedFloorAreDrivableGround) {
  World world = World::from_string(R"(
<mujoco>
  <include file="robot.xml"/>
  <worldbody>
    <geom name="floor" type="plane" size="10 10 0.1"/>
    <geom name="floor_ramp" type="box" pos="4 0 0.1" euler="0 -0.1 0" size="1.5 1 0.05"/>
    <geom name="floor_platform" type="box" pos="7 0 0.15" size="1.5 1 0.15"/>
    <geom name="subfloor_crate" type="box" pos="2 2 0.2" size="0.2 0.2 0.2"/>
  </worldbody>
</mujoco>)",
                                   test::worlds_dir());
  const auto geoms = obstacle_geoms(world);
  ASSERT_EQ(geoms.size(), 1u);
  EXPECT_DOUBLE_EQ(geoms[0].aabb_W().center().x(), 2.0);
}

TEST(GroundTruth, VoxelsAreAttributedToBodies) {
  World world = World::from_string(kTwoObstacles, test::worlds_dir());
  VoxelizeOptions options;
  options.voxel_size_m = 0.1;
  const auto bodies = voxelize_bodies(obstacle_geoms(world), options);
  ASSERT_EQ(bodies.size(), 2u);
  EXPECT_EQ(bodies[0].body_name, "crate");
  for (const auto& k : bodies[0].voxels) EXPECT_GE(voxel_center(k, 0.1).x(), 2.7);
  for (const auto& k : bodies[1].voxels) EXPECT_GE(voxel_center(k, 0.1).y(), 1.8);
  EXPECT_EQ(merge(bodies).size(), bodies[0].voxels.size() + bodies[1].voxels.size());
}

TEST(GroundTruth, FootprintsInHeightBand) {
  World world = World::from_string(kTwoObstacles, test::worlds_dir());
  const auto geoms = obstacle_geoms(world);
  const auto low = footprints(geoms, 0.1, 0.05, 0.5);
  ASSERT_EQ(low.size(), 2u);
  EXPECT_EQ(low[0].cells.size(), 4u * 6u);  // crate x 2.81..3.19, y -0.29..0.29
  EXPECT_LE(low[1].cells.size(), 4u);       // pole of radius 0.05 at a cell corner
  EXPECT_GE(low[1].cells.size(), 1u);
  const auto high = footprints(geoms, 0.1, 0.5, 1.8);
  EXPECT_TRUE(high[0].cells.empty());  // the crate ends at 0.4 m
  EXPECT_FALSE(high[1].cells.empty());
}

TEST(GroundTruth, MeshIsItsTrianglesNotItsBoundingBox) {
  // A wedge given by its vertices only: MuJoCo 2.2.2 draws (and keeps as faces) its convex hull.
  World world = World::from_string(R"(
<mujoco>
  <asset><mesh name="wedge" vertex="0 0 0  0.4 0 0  0 0.3 0  0 0 0.2  0.4 0 0.2  0 0.3 0.2"/></asset>
  <worldbody><body name="ramp" pos="1 1 0"><geom type="mesh" mesh="wedge"/></body></worldbody>
</mujoco>)");
  const auto geoms = obstacle_geoms(world);
  ASSERT_EQ(geoms.size(), 1u);
  EXPECT_EQ(geoms[0].shape, ShapeType::mesh);
  EXPECT_TRUE(geoms[0].mesh->closed());
  const double vertices[6][3] = {{0, 0, 0}, {0.4, 0, 0}, {0, 0.3, 0}, {0, 0, 0.2}, {0.4, 0, 0.2}, {0, 0.3, 0.2}};
  for (const auto& v : vertices) {  // every vertex on the surface, where the model says
    EXPECT_NEAR(geoms[0].signed_distance_m(Eigen::Vector3d(1 + v[0], 1 + v[1], v[2])), 0.0, 1e-6);
  }
  EXPECT_LT(geoms[0].signed_distance_m({1.1, 1.05, 0.1}), -0.04);  // inside
  // The corner (0.4, 0.3) of the bounding box is outside, 0.4 * 0.3 / 0.5 m from the slanted face.
  EXPECT_NEAR(geoms[0].signed_distance_m({1.4, 1.3, 0.1}), 0.4 * 0.3 / 0.5, 1e-6);
}

TEST(GroundTruth, RayHitsKnownBox) {
  World world = World::from_string(kTwoObstacles, test::worlds_dir());
  const RayHit hit = cast_ray(world, {0.5, 0.1, 0.2}, {2.0, 0.0, 0.0});
  ASSERT_TRUE(hit.hit);
  EXPECT_NEAR(hit.distance_m, 2.31, 1e-9);
  EXPECT_EQ(hit.body_name, "crate");
  EXPECT_FALSE(cast_ray(world, {0.5, 0.1, 0.2}, {1.0, 0.0, 0.0}, 2.0).hit);
  EXPECT_FALSE(cast_ray(world, {0.5, 0.1, 0.2}, {-1.0, 0.0, 0.0}).hit);
  // From inside the robot looking back at it: group 2 is ignored unless asked for.
  const RayHit robot = cast_ray(world, {-1.0, 0.0, 0.15}, {1.0, 0.0, 0.0}, 10.0, 0b111);
  ASSERT_TRUE(robot.hit);
  EXPECT_NEAR(robot.distance_m, 1.0 - 0.225, 1e-3);
  EXPECT_THROW(cast_ray(world, {0, 0, 0}, {0, 0, 0}), std::invalid_argument);
}

}  // namespace
}  // namespace stvl::truth

// STVL's own arithmetic (ros2 403d9ed, noetic-devel 5e06daf) against ours: the mark's voxel index
// (MarkRounding) and the depth camera's clearing frustum (FrustumGeometry). Every expected number below is
// worked out by hand from STVL's formulas; each test fails with the bench's floor / ideal pyramid.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "mapping/frustum.hpp"
#include "mapping/voxel_map.hpp"
#include "test_helpers.hpp"

namespace stvl::mapping {
namespace {

using test::camera_looking_along_x;
using test::cloud;
using test::wide_source;

StvlConfig config_with(double voxel_size_m, MarkRounding rounding, FrustumGeometry geometry = FrustumGeometry::kIdeal) {
  StvlConfig config;
  config.voxel_size_m = voxel_size_m;
  config.mark_rounding = rounding;
  config.frustum_geometry = geometry;
  return config;
}

TEST(StvlGeometryConfig, NamesParseAndRoundTrip) {
  EXPECT_EQ(parse_mark_rounding("floor"), MarkRounding::kFloor);
  EXPECT_EQ(parse_mark_rounding("stvl"), MarkRounding::kStvl);
  EXPECT_EQ(parse_frustum_geometry("ideal"), FrustumGeometry::kIdeal);
  EXPECT_EQ(parse_frustum_geometry("stvl"), FrustumGeometry::kStvl);
  EXPECT_EQ(to_string(MarkRounding::kStvl), "stvl");
  EXPECT_EQ(to_string(FrustumGeometry::kIdeal), "ideal");
  try {
    parse_mark_rounding("trunc");
    ADD_FAILURE() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("floor"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("stvl"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_frustum_geometry("pyramid"), std::invalid_argument);
  // Today's behaviour stays the default.
  const StvlConfig defaults;
  EXPECT_EQ(defaults.mark_rounding, MarkRounding::kStvl);  // STVL's behaviour unless a scenario asks for ours
  EXPECT_EQ(defaults.frustum_geometry, FrustumGeometry::kStvl);
  StvlConfig bad;
  bad.mark_rounding = static_cast<MarkRounding>(7);
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

// vs = 0.125 is exact in float and 1/vs = 8 exactly, so every product below is exact:
// key = trunc(shifted * 8), shifted = p - vs on x, y when negative, and on z when *y* is negative.
TEST(StvlMarkRounding, ShiftedTruncationWithTheYSignTestOnZ) {
  const VoxelMap stvl(config_with(0.125, MarkRounding::kStvl));
  const VoxelMap ours(config_with(0.125, MarkRounding::kFloor));
  struct Case {
    Eigen::Vector3d p;
    VoxelKey stvl, floor;
  };
  const std::vector<Case> cases = {
      // x = -0.25, an exact negative multiple: (-0.25 - 0.125) * 8 = -3 (floor: -2); y >= 0, so z is not shifted.
      {{-0.25, 0.5, 0.25}, {-3, 4, 2}, {-2, 4, 2}},
      // y < 0: y -> (-0.375) * 8 = -3 (floor -2); z >= 0 is shifted too: (0.25 - 0.125) * 8 = 1 (floor 2).
      {{0.25, -0.25, 0.25}, {2, -3, 1}, {2, -2, 2}},
      // y >= 0, z in (-vs, 0): trunc(-0.5) = 0 (floor -1): voxel 0 spans (-vs, vs) on z.
      {{0.0625, 0.0625, -0.0625}, {0, 0, 0}, {0, 0, -1}},
      // y >= 0, z = -0.1875: trunc(-1.5) = -1 (floor -2): every negative z one voxel higher.
      {{0.0625, 0.0625, -0.1875}, {0, 0, -1}, {0, 0, -2}},
      // y < 0, z = 0 exactly: (0 - 0.125) * 8 = -1 (floor 0).
      {{0.0625, -0.0625, 0.0}, {0, -1, -1}, {0, -1, 0}},
      // y < 0, z in (0, 2 vs): trunc(0.5) = 0 (floor 1).
      {{0.0625, -0.0625, 0.1875}, {0, -1, 0}, {0, -1, 1}},
      // y < 0, z < 0 not on a boundary: like floor on every axis (control).
      {{-0.0625, -0.0625, -0.1875}, {-1, -1, -2}, {-1, -1, -2}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(testing::Message() << c.p.transpose());
    EXPECT_EQ(stvl.mark_key_of(c.p), c.stvl);
    EXPECT_EQ(ours.mark_key_of(c.p), c.floor);
    EXPECT_EQ(stvl.key_of(c.p), c.floor);  // lookups floor whatever the mark does
  }
}

// vs = 0.05 is narrowed to float as STVL's grid does: vs = 0.0500000007450580596923828125, 1/vs = 19.9999997...
TEST(StvlMarkRounding, FloatVoxelSizeAtFiveCentimetres) {
  const VoxelMap stvl(config_with(0.05, MarkRounding::kStvl));
  const VoxelMap ours(config_with(0.05, MarkRounding::kFloor));
  // (0.12, -0.01, 0.12): x 2.3999999 -> 2; y (-0.01 - vs) * (1/vs) = -1.1999999 -> -1; z shifted by y's sign:
  // (0.12 - vs) * (1/vs) = 1.3999999 -> 1 (floor 2).
  EXPECT_EQ(stvl.mark_key_of({0.12f, -0.01f, 0.12f}), (VoxelKey{2, -1, 1}));
  EXPECT_EQ(ours.mark_key_of({0.12f, -0.01f, 0.12f}), (VoxelKey{2, -1, 2}));
  // (0.03, 0.07, -0.03): z -0.5999999 -> 0 (floor -1).
  EXPECT_EQ(stvl.mark_key_of({0.03f, 0.07f, -0.03f}), (VoxelKey{0, 1, 0}));
  EXPECT_EQ(ours.mark_key_of({0.03f, 0.07f, -0.03f}), (VoxelKey{0, 1, -1}));
  // float(-0.05) == -vs: x (-vs - vs) / vs = -2 exactly; y float(0.2) = 4 vs exactly -> 4; z -vs / vs = -1 exactly
  // (floor: -0.05000000075 / 0.05 = -1.0000000149 -> -2).
  EXPECT_EQ(stvl.mark_key_of({-0.05f, 0.2f, -0.05f}), (VoxelKey{-2, 4, -1}));
  EXPECT_EQ(ours.mark_key_of({-0.05f, 0.2f, -0.05f}), (VoxelKey{-2, 4, -2}));
  // 5.0 * (1/vs) = 99.99999851 -> 99: the float voxel size shows at 5 m (floor(5.0 / 0.05) = 100).
  EXPECT_EQ(stvl.mark_key_of({5.0, 0.0, 0.0}).x, 99);
  EXPECT_EQ(ours.mark_key_of({5.0, 0.0, 0.0}).x, 100);
}

TEST(StvlMarkRounding, MarkStoresTheStvlKey) {
  VoxelMap stvl(config_with(0.125, MarkRounding::kStvl));
  VoxelMap ours(config_with(0.125, MarkRounding::kFloor));
  const auto camera = camera_looking_along_x({-5, 0, 0});
  const Eigen::Matrix3Xf points = cloud({{0.25f, -0.25f, 0.25f}, {0.0625f, 0.0625f, -0.0625f}});
  ASSERT_EQ(stvl.mark(points, camera, wide_source(), 1.0), 2u);
  ASSERT_EQ(ours.mark(points, camera, wide_source(), 1.0), 2u);
  EXPECT_EQ(stvl.voxel_keys(), (std::vector<VoxelKey>{{0, 0, 0}, {2, -3, 1}}));
  EXPECT_EQ(ours.voxel_keys(), (std::vector<VoxelKey>{{0, 0, -1}, {2, -2, 2}}));
}

// h = 1.04, v = 0.7 rad (cos 0.52 = 0.867819, cos 0.35 = 0.939373, tan 0.52 = 0.572562, tan 0.35 = 0.365028).
// STVL: far plane at 4 * 0.867819 * 0.939373 = 3.26082 m; near (min_z 0.5) at 0.40760 m; |x| <= z * 0.609517;
// |y| <= z * 0.365028. Ideal: z in [0.5, 4], |x| <= z * 0.572562, |y| <= z * 0.365028.
constexpr double kH = 1.04, kV = 0.7, kNear = 0.5, kFar = 4.0;

void expect_in(const Eigen::Isometry3d& T, const Eigen::Vector3d& p_C, bool in_stvl, bool in_ideal) {
  const DepthCameraFrustum stvl(T, kH, kV, kNear, kFar, FrustumGeometry::kStvl);
  const DepthCameraFrustum ideal(T, kH, kV, kNear, kFar, FrustumGeometry::kIdeal);
  const Eigen::Vector3d p_W = T * p_C;
  EXPECT_EQ(stvl.contains(p_W), in_stvl) << "stvl, camera-frame point " << p_C.transpose();
  EXPECT_EQ(ideal.contains(p_W), in_ideal) << "ideal, camera-frame point " << p_C.transpose();
  // The culling never drops what contains() keeps.
  if (in_stvl) {
    EXPECT_TRUE(stvl.may_intersect(Eigen::AlignedBox3d(p_W, p_W)));
  }
  if (in_ideal) {
    EXPECT_TRUE(ideal.may_intersect(Eigen::AlignedBox3d(p_W, p_W)));
  }
}

TEST(StvlFrustum, PlanesSitWhereStvlPutsThem) {
  for (const Eigen::Isometry3d& T :
       {Eigen::Isometry3d(Eigen::Isometry3d::Identity()), camera_looking_along_x({1.0, 2.0, 0.5}, 0.3)}) {
    SCOPED_TRACE(testing::Message() << "camera at " << T.translation().transpose());
    // Far: on the axis, 3.25 is inside both; 3.27 is past STVL's far plane (3.2608), inside the ideal one.
    expect_in(T, {0, 0, 3.0}, true, true);
    expect_in(T, {0, 0, 3.25}, true, true);
    expect_in(T, {0, 0, 3.27}, false, true);
    expect_in(T, {0, 0, 3.99}, false, true);
    expect_in(T, {0, 0, 4.01}, false, false);
    // Near: 0.45 is in front of the ideal near plane (0.5) but behind STVL's (0.4076); 0.40 is outside both.
    expect_in(T, {0, 0, 0.45}, true, false);
    expect_in(T, {0, 0, 0.40}, false, false);
    // Sides at z = 2: STVL |x| <= 1.21903, ideal |x| <= 1.14512.
    expect_in(T, {1.14, 0, 2}, true, true);
    expect_in(T, {1.20, 0, 2}, true, false);
    expect_in(T, {-1.20, 0, 2}, true, false);
    expect_in(T, {1.23, 0, 2}, false, false);
    expect_in(T, {-1.23, 0, 2}, false, false);
    // Top and bottom at z = 2: |y| <= 0.73006 in both (the vertical half-angle is exact).
    expect_in(T, {0, 0.72, 2}, true, true);
    expect_in(T, {0, -0.72, 2}, true, true);
    expect_in(T, {0, 0.74, 2}, false, false);
    expect_in(T, {0, -0.74, 2}, false, false);
    // Near a far corner: z = 3.25, x = 1.9 (STVL 1.98093, ideal 1.86083), y = 1.1 (1.18634).
    expect_in(T, {1.9, 1.1, 3.25}, true, false);
    expect_in(T, {-1.9, -1.1, 3.25}, true, false);
    expect_in(T, {1.9, 1.2, 3.25}, false, false);
    // Behind the camera.
    expect_in(T, {0, 0, -1}, false, false);
  }
}

TEST(StvlFrustum, ApexOnThePlanesCountsAsInside) {
  // min_z = 0: the apex is the anchor of the four side planes and of the near plane (a zero vector after
  // normalisation, dot 0, not > 0) and lies behind the far plane.
  const DepthCameraFrustum stvl(Eigen::Isometry3d::Identity(), kH, kV, 0.0, kFar, FrustumGeometry::kStvl);
  EXPECT_TRUE(stvl.contains({0, 0, 0}));
  EXPECT_FALSE(stvl.contains({0, 0, -1e-9}));
}

// The culling stays conservative for STVL's wider and shorter frustum: any sampled point of a random box that
// contains() keeps means may_intersect() is true.
TEST(StvlFrustum, MayIntersectIsConservative) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coord(-5.0, 5.0), size(0.0, 1.0), unit(0.0, 1.0);
  const Eigen::Isometry3d T = camera_looking_along_x({0.3, -0.2, 0.1}, 0.4);
  const DepthCameraFrustum f(T, kH, kV, kNear, kFar, FrustumGeometry::kStvl);
  int hits = 0;
  for (int i = 0; i < 4000; ++i) {
    const Eigen::Vector3d lo(coord(rng), coord(rng), coord(rng) / 2);
    const Eigen::Vector3d hi = lo + Eigen::Vector3d(size(rng), size(rng), size(rng));
    const Eigen::AlignedBox3d box(lo, hi);
    for (int j = 0; j < 20; ++j) {
      const Eigen::Vector3d p = lo + (hi - lo).cwiseProduct(Eigen::Vector3d(unit(rng), unit(rng), unit(rng)));
      if (!f.contains(p)) continue;
      ++hits;
      ASSERT_TRUE(f.may_intersect(box)) << "box " << lo.transpose() << " .. " << hi.transpose();
      break;
    }
  }
  EXPECT_GT(hits, 100);
}

// A voxel only one geometry contains is accelerated away by that geometry only, in both walks. vs = 0.05, camera
// at the origin looking along +z (optical = world), voxel (0, 0, 66): centre z = 3.325 (STVL: 66 vs + vs/2 =
// 3.3250000496). decay 100 s, age 1 s, decay_acceleration 1000: 1000 / 6 = 166.7 s taken > 99 s left.
TEST(StvlFrustum, MapAcceleratesOnlyInsideTheChosenGeometry) {
  ObservationSource source = wide_source();
  source.horizontal_fov_rad = kH;
  source.vertical_fov_rad = kV;
  source.decay_acceleration_per_s3 = 1000.0;
  const VoxelKey on_axis{0, 0, 66};
  // Beyond STVL's far plane (max_z 4: 3.2608) but inside max_z: the ideal pyramid clears it, STVL's does not.
  // In front of the ideal near plane (min_z 4, max_z 10) but behind STVL's (3.2608): the reverse. The second
  // case's leaf (z keys 64..71, centres 3.225..3.575 m) lies wholly outside the ideal pyramid, so the bounded walk
  // finds it only if its culling uses STVL's extent.
  struct Case {
    double min_z, max_z;
    bool cleared_by_stvl, cleared_by_ideal;
  };
  for (const Case& c : {Case{0.5, 4.0, false, true}, Case{4.0, 10.0, true, false}}) {
    source.min_z_m = c.min_z;
    source.max_z_m = c.max_z;
    for (const ClearingWalk walk : {ClearingWalk::kBounded, ClearingWalk::kFullWalk}) {
      for (const FrustumGeometry geometry : {FrustumGeometry::kStvl, FrustumGeometry::kIdeal}) {
        SCOPED_TRACE(testing::Message() << "min_z " << c.min_z << ", " << to_string(walk) << ", "
                                        << to_string(geometry));
        StvlConfig config = config_with(0.05, MarkRounding::kFloor, geometry);
        config.voxel_decay_s = 100.0;
        config.clearing_walk = walk;
        VoxelMap map(config);
        map.set_voxels({{on_axis, 0.0}});
        std::vector<VoxelKey> cleared;
        map.clear({{Eigen::Isometry3d::Identity(), source, nullptr}}, 1.0, &cleared);
        const bool expect_cleared = geometry == FrustumGeometry::kStvl ? c.cleared_by_stvl : c.cleared_by_ideal;
        EXPECT_EQ(map.contains(on_axis), !expect_cleared);
        EXPECT_EQ(cleared.size(), expect_cleared ? 1u : 0u);
      }
    }
  }
}

// A voxel beside the axis, inside STVL's wider side but outside the ideal one: (23, 0, 40) centre (1.175, 0.025,
// 2.025); STVL's half-width there 2.025 * 0.609517 = 1.2343, ideal 1.1594.
TEST(StvlFrustum, MapUsesTheWiderSides) {
  ObservationSource source = wide_source();
  source.horizontal_fov_rad = kH;
  source.vertical_fov_rad = kV;
  source.min_z_m = 0.5;
  source.max_z_m = 4.0;
  source.decay_acceleration_per_s3 = 1000.0;
  const VoxelKey beside{23, 0, 40};
  for (const ClearingWalk walk : {ClearingWalk::kBounded, ClearingWalk::kFullWalk}) {
    for (const FrustumGeometry geometry : {FrustumGeometry::kStvl, FrustumGeometry::kIdeal}) {
      SCOPED_TRACE(testing::Message() << to_string(walk) << ", " << to_string(geometry));
      StvlConfig config = config_with(0.05, MarkRounding::kFloor, geometry);
      config.voxel_decay_s = 100.0;
      config.clearing_walk = walk;
      VoxelMap map(config);
      map.set_voxels({{beside, 0.0}});
      map.clear({{Eigen::Isometry3d::Identity(), source, nullptr}}, 1.0);
      EXPECT_EQ(map.contains(beside), geometry == FrustumGeometry::kIdeal);
    }
  }
}

// Random voxels, a moving camera: with STVL's geometry and rounding the bounded walk equals the full walk once its
// expiry backlog is worked off (the culling drops no voxel the frustum test would have kept).
TEST(StvlFrustum, BoundedWalkEqualsFullWalk) {
  StvlConfig config = config_with(0.05, MarkRounding::kStvl, FrustumGeometry::kStvl);
  config.voxel_decay_s = 3.0;
  VoxelMap bounded(config);
  config.clearing_walk = ClearingWalk::kFullWalk;
  VoxelMap full(config);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coord(-4.0, 4.0), age(0.0, 4.0);
  std::vector<Voxel> seed;
  for (int i = 0; i < 4000; ++i)
    seed.push_back({bounded.key_of({coord(rng), coord(rng), coord(rng) / 3}), 2.0 - age(rng)});
  bounded.set_voxels(seed);
  full.set_voxels(seed);
  ObservationSource source = wide_source();
  source.horizontal_fov_rad = kH;
  source.vertical_fov_rad = kV;
  source.min_z_m = 0.3;
  source.max_z_m = 3.0;
  source.decay_acceleration_per_s3 = 5.0;
  for (int frame = 0; frame < 20; ++frame) {
    const double t = 2.0 + 0.1 * frame;
    const auto camera = camera_looking_along_x({-3.0 + 0.3 * frame, 0.1, 0.05}, 0.25 * frame);
    std::vector<Eigen::Vector3f> points;
    for (int i = 0; i < 200; ++i)
      points.emplace_back(camera.translation().cast<float>() +
                          Eigen::Vector3f(coord(rng), coord(rng), coord(rng) / 3).cast<float>());
    const Eigen::Matrix3Xf points_W = cloud(points);
    bounded.clear({{camera, source, nullptr}}, t);
    full.clear({{camera, source, nullptr}}, t);
    bounded.mark(points_W, camera, source, t);
    full.mark(points_W, camera, source, t);
  }
  const double t_end = 2.0 + 0.1 * 19;
  while (bounded.clear({}, t_end).expiry_backlog > 0) {
  }
  full.clear({}, t_end);
  EXPECT_TRUE(test::same_voxels(bounded.voxels(), full.voxels()));
  EXPECT_GT(full.size(), 100u);
}

TEST(StvlGeometryConfig, VdbKeepsBothChoices) {
  VoxelMap map(config_with(0.05, MarkRounding::kStvl, FrustumGeometry::kStvl));
  map.set_voxels({{{1, 2, 3}, 1.0}});
  const std::string path = ::testing::TempDir() + "stvl_geometry_test.vdb";
  map.save_vdb(path);
  const VoxelMap loaded = VoxelMap::load_vdb(path);
  EXPECT_EQ(loaded.config().mark_rounding, MarkRounding::kStvl);
  EXPECT_EQ(loaded.config().frustum_geometry, FrustumGeometry::kStvl);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace stvl::mapping

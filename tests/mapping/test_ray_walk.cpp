// The optimized ray walk (mapping/ray_walk.hpp) against its plain twin (mapping/reference/): same voxels in the
// same order on random rays, with every block present and with random blocks missing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "mapping/ray_walk.hpp"
#include "mapping/reference/ray_walk_reference.hpp"
#include "test_helpers.hpp"

namespace stvl::mapping {
namespace {

using Keys = std::vector<VoxelKey>;

std::string describe(const Eigen::Vector3d& s, const Eigen::Vector3d& e) {
  char text[256];
  std::snprintf(text, sizeof text, "s = (%.17g, %.17g, %.17g), e = (%.17g, %.17g, %.17g)", s.x(), s.y(), s.z(), e.x(),
                e.y(), e.z());
  return text;
}

// Rays in voxel units, drawn from kinds that stress the contract.
class RayGenerator {
 public:
  explicit RayGenerator(std::uint64_t seed) : rng_(seed) {}

  void next(Eigen::Vector3d& s, Eigen::Vector3d& e) {
    const int kind = pick(0, 9);
    switch (kind) {
      case 0:
      case 1: {  // generic, around the origin (negative coordinates included)
        s = uniform_point(200.0);
        e = s + random_direction() * length(300.0);
        return;
      }
      case 2: {  // axis-aligned or parallel to a coordinate plane
        s = uniform_point(100.0);
        Eigen::Vector3d d = random_direction() * length(100.0);
        for (int a = 0; a < 3; ++a)
          if (pick(0, 1) == 0) d[a] = 0.0;
        e = s + d;
        return;
      }
      case 3:
      case 4: {  // lattice: start on integer / half / quarter coordinates, integer direction: exact edge and
                 // corner crossings (ties), endpoints on faces, edges and corners
        for (int a = 0; a < 3; ++a) s[a] = pick(-40, 40) + 0.25 * pick(0, 3);
        Eigen::Vector3d d;
        const int scale = pick(1, 5);
        for (int a = 0; a < 3; ++a) d[a] = scale * pick(-6, 6);
        if (pick(0, 2) == 0) d = d.normalized() * std::round(d.norm());  // diagonal through corners as well
        e = s + d;
        return;
      }
      case 5: {  // the diagonal through voxel corners from a centre or a corner, all signs
        const double base = pick(0, 1) == 0 ? 0.5 : 0.0;
        for (int a = 0; a < 3; ++a) s[a] = pick(-30, 30) + base;
        const int n = pick(1, 40);
        for (int a = 0; a < 3; ++a) e[a] = s[a] + (pick(0, 1) == 0 ? -n : n) * (pick(0, 3) == 0 ? 0 : 1);
        return;
      }
      case 6: {  // zero length, or inside one voxel
        s = uniform_point(50.0);
        e = pick(0, 1) == 0 ? s : Eigen::Vector3d(s.array().floor() + 0.5);
        return;
      }
      case 7: {  // very long (sometimes)
        s = uniform_point(1000.0);
        e = s + random_direction() * (pick(0, 20) == 0 ? 20000.0 : 2000.0);
        return;
      }
      case 8: {  // tiny or subnormal direction components, starts a few ulps off a face
        s = uniform_point(20.0).array().round();
        for (int a = 0; a < 3; ++a) {
          const int nudge = pick(-2, 2);
          for (int i = 0; i < std::abs(nudge); ++i) s[a] = std::nextafter(s[a], nudge > 0 ? 1e300 : -1e300);
        }
        Eigen::Vector3d d = random_direction() * length(50.0);
        const double tiny[] = {1e-17, -1e-17, 1e-300, -1e-300, 4e-310, -4e-310, 0.0};
        d[pick(0, 2)] = tiny[pick(0, 6)];
        e = s + d;
        return;
      }
      default: {  // ends a few ulps either side of a face
        s = uniform_point(60.0);
        e = (s + random_direction() * length(60.0)).array().round();
        for (int a = 0; a < 3; ++a) {
          const int nudge = pick(-1, 1);
          if (nudge != 0) e[a] = std::nextafter(e[a], nudge > 0 ? 1e300 : -1e300);
        }
        return;
      }
    }
  }

  int pick(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  std::mt19937_64& rng() { return rng_; }

 private:
  Eigen::Vector3d uniform_point(double half_extent) {
    std::uniform_real_distribution<double> u(-half_extent, half_extent);
    return {u(rng_), u(rng_), u(rng_)};
  }
  Eigen::Vector3d random_direction() {
    std::normal_distribution<double> n(0.0, 1.0);
    Eigen::Vector3d d(n(rng_), n(rng_), n(rng_));
    return d.norm() > 1e-9 ? d.normalized() : Eigen::Vector3d::UnitX();
  }
  double length(double max_length) {  // log-uniform from a tenth of a voxel
    std::uniform_real_distribution<double> u(std::log(0.1), std::log(max_length));
    return std::exp(u(rng_));
  }
  std::mt19937_64 rng_;
};

// True when, somewhere on the walk, two axes reach their next face at the same t (an edge or corner crossing).
bool has_tie(const Eigen::Vector3d& s, const Eigen::Vector3d& e, const Keys& keys) {
  detail::RayAxes ray;
  if (!detail::setup_ray(s, e, ray)) return false;
  for (const VoxelKey& k : keys) {
    const std::int64_t t[3] = {ray.exit_t(0, k.x), ray.exit_t(1, k.y), ray.exit_t(2, k.z)};
    const std::int64_t t_min = std::min({t[0], t[1], t[2]});
    if (t_min < detail::kOne && (t[0] == t_min) + (t[1] == t_min) + (t[2] == t_min) >= 2) return true;
  }
  return false;
}

std::uint64_t mix(std::uint64_t x) {  // splitmix64 finaliser
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// A block is present with probability percent / 100, decided by a hash of its origin and the seed.
struct RandomBlocks {
  std::uint64_t seed;
  int percent;
  bool present(const VoxelKey& origin) const {
    const std::uint64_t h =
        mix(seed ^ mix(static_cast<std::uint32_t>(origin.x) ^
                       mix(static_cast<std::uint32_t>(origin.y) ^ mix(static_cast<std::uint32_t>(origin.z)))));
    return static_cast<int>(h % 100) < percent;
  }
};

VoxelKey block_of(const VoxelKey& k) { return {k.x & ~7, k.y & ~7, k.z & ~7}; }

VoxelKey floor_key(const Eigen::Vector3d& p) {
  return {static_cast<int>(std::floor(p.x())), static_cast<int>(std::floor(p.y())),
          static_cast<int>(std::floor(p.z()))};
}

// True when the walk stopped on t >= 1 without reaching the end voxel (its last voxel is no neighbour of the end).
bool stopped_beside_end(const Eigen::Vector3d& e, const Keys& keys) {
  if (keys.empty()) return false;
  const VoxelKey end = floor_key(e), last = keys.back();
  return std::abs(end.x - last.x) + std::abs(end.y - last.y) + std::abs(end.z - last.z) != 1;
}

constexpr int kRays = 40000;

TEST(RayWalk, EveryBlockPresentMatchesReference) {
  RayGenerator gen(1);
  int tie_rays = 0, empty_rays = 0, beside_end = 0, mismatches = 0;
  std::size_t voxels = 0;
  for (int i = 0; i < kRays; ++i) {
    Eigen::Vector3d s, e;
    gen.next(s, e);
    const Keys expected = reference::ray_voxels(s, e);
    const Keys got = ray_voxels(s, e);
    voxels += expected.size();
    tie_rays += has_tie(s, e, expected);
    empty_rays += expected.empty();
    beside_end += stopped_beside_end(e, expected);
    if (got != expected && ++mismatches <= 5)
      ADD_FAILURE() << describe(s, e) << ": " << got.size() << " voxels, reference " << expected.size();
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(tie_rays, kRays / 20) << "the generator should produce edge and corner crossings";
  EXPECT_GT(empty_rays, kRays / 50);
  EXPECT_GT(beside_end, 10) << "some rays should stop on t >= 1 beside the end voxel";
  std::printf("%d rays: %d with edge/corner ties, %d empty, %d stopped beside the end voxel, %zu voxels\n", kRays,
              tie_rays, empty_rays, beside_end, voxels);
  EXPECT_GT(voxels, static_cast<std::size_t>(kRays) * 20);
}

TEST(RayWalk, MissingBlocksAreSkippedAndTheRestMatchesReference) {
  RayGenerator gen(2);
  const int densities[] = {0, 5, 30, 70, 95};
  int mismatches = 0, end_block_missing = 0;
  for (int i = 0; i < kRays; ++i) {
    Eigen::Vector3d s, e;
    gen.next(s, e);
    const RandomBlocks blocks{static_cast<std::uint64_t>(i) * 7919u, densities[gen.pick(0, 4)]};
    Keys expected;
    for (const VoxelKey& k : reference::ray_voxels(s, e))
      if (blocks.present(block_of(k))) expected.push_back(k);
    if (e.allFinite() && !blocks.present(block_of(floor_key(e)))) ++end_block_missing;
    const int present = 1;
    Keys got;
    bool wrong_block = false;
    walk_ray_blocks(
        s, e, [&](const VoxelKey& origin) { return blocks.present(origin) ? &present : nullptr; },
        [&](const int* block, const VoxelKey& key) {
          wrong_block |= block != &present;
          got.push_back(key);
        });
    if ((got != expected || wrong_block) && ++mismatches <= 5)
      ADD_FAILURE() << describe(s, e) << " (blocks " << blocks.percent << "%): " << got.size() << " voxels, reference "
                    << expected.size();
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(end_block_missing, kRays / 10);
}

TEST(RayWalk, ContractByHand) {
  using V = Eigen::Vector3d;
  // Axis-aligned: start voxel in, end voxel out.
  EXPECT_EQ(ray_voxels(V(0.5, 0.5, 0.5), V(3.5, 0.5, 0.5)), (Keys{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}));
  // Negative coordinates and direction.
  EXPECT_EQ(ray_voxels(V(-0.5, 0.2, -0.1), V(-0.5, -2.2, -0.1)), (Keys{{-1, 0, -1}, {-1, -1, -1}, {-1, -2, -1}}));
  // Through corners: x before y before z on a tie.
  EXPECT_EQ(ray_voxels(V(0.5, 0.5, 0.5), V(2.5, 2.5, 0.5)), (Keys{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {2, 1, 0}}));
  EXPECT_EQ(ray_voxels(V(0.5, 0.5, 0.5), V(1.5, 1.5, 1.5)), (Keys{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}));
  EXPECT_EQ(ray_voxels(V(0.5, -0.5, 0.5), V(1.5, 0.5, -0.5)), (Keys{{0, -1, 0}, {1, -1, 0}, {1, 0, 0}}));
  // Zero length, one voxel, bad input.
  EXPECT_TRUE(ray_voxels(V(1.2, 3.4, -5.6), V(1.2, 3.4, -5.6)).empty());
  EXPECT_TRUE(ray_voxels(V(1.2, 3.4, -5.6), V(1.9, 3.1, -5.1)).empty());
  EXPECT_TRUE(ray_voxels(V(0.5, 0.5, std::nan("")), V(3.5, 0.5, 0.5)).empty());
  EXPECT_TRUE(ray_voxels(V(0.5, 0.5, 0.5), V(std::ldexp(1.0, 30), 0.5, 0.5)).empty());
  // Starting on a face and moving down: the start voxel is visited, then left at t = 0.
  EXPECT_EQ(ray_voxels(V(2.0, 0.5, 0.5), V(0.5, 0.5, 0.5)), (Keys{{2, 0, 0}, {1, 0, 0}}));
  // Ending on a face moving up: the voxel behind the face is the end voxel, not visited.
  EXPECT_EQ(ray_voxels(V(0.5, 0.5, 0.5), V(2.0, 0.5, 0.5)), (Keys{{0, 0, 0}, {1, 0, 0}}));
}

TEST(RayWalk, PathIsSixConnectedFromTheStartVoxelAndNeverReachesTheEnd) {
  RayGenerator gen(3);
  for (int i = 0; i < 5000; ++i) {
    Eigen::Vector3d s, e;
    gen.next(s, e);
    const Keys keys = ray_voxels(s, e);
    if (keys.empty()) continue;
    const VoxelKey end = floor_key(e);
    ASSERT_EQ(keys.front(), floor_key(s)) << describe(s, e);
    for (std::size_t j = 0; j < keys.size(); ++j) {
      ASSERT_NE(keys[j], end) << describe(s, e);
      if (j == 0) continue;
      const int dist = std::abs(keys[j].x - keys[j - 1].x) + std::abs(keys[j].y - keys[j - 1].y) +
                       std::abs(keys[j].z - keys[j - 1].z);
      ASSERT_EQ(dist, 1) << describe(s, e) << " at " << j;
    }
  }
}

// Ray-cast clearing removes exactly the walk's voxels, with the points keyed as mark() keys them.
TEST(RayWalk, RaycastClearingRemovesTheWalksVoxels) {
  StvlConfig config;
  config.voxel_size_m = 0.05;
  config.clearing_mode = ClearingMode::kRaycast;
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  for (int trial = 0; trial < 20; ++trial) {
    VoxelMap map(config);
    std::vector<Voxel> filled;  // a solid cube of 32^3 voxels around the camera, so no block is skipped
    for (int x = -16; x < 16; ++x)
      for (int y = -16; y < 16; ++y)
        for (int z = -16; z < 16; ++z) filled.push_back({{x, y, z}, 0.0});
    map.set_voxels(filled);
    const Eigen::Vector3d origin_W(u(rng) * 0.3, u(rng) * 0.3, u(rng) * 0.3);
    Eigen::Matrix3Xf points_W(3, 4);
    for (int i = 0; i < 4; ++i) points_W.col(i) = Eigen::Vector3d(u(rng), u(rng), u(rng)).cast<float>();
    ClearingObservation obs;
    obs.T_world_camera = test::camera_looking_along_x(origin_W);
    obs.source = test::wide_source();
    obs.points_W = &points_W;
    map.clear({obs}, 0.1);
    VoxelSet expected_removed;
    for (int i = 0; i < 4; ++i)
      for (const VoxelKey& k :
           reference::ray_voxels(origin_W / config.voxel_size_m, points_W.col(i).cast<double>() / config.voxel_size_m))
        expected_removed.insert(k);
    VoxelSet kept;
    for (const VoxelKey& k : map.voxel_keys()) kept.insert(k);
    std::size_t removed = 0;
    for (const Voxel& v : filled) {
      const bool gone = kept.count(v.key) == 0;
      removed += gone;
      EXPECT_EQ(gone, expected_removed.count(v.key) == 1)
          << "trial " << trial << " voxel " << v.key.x << " " << v.key.y << " " << v.key.z;
    }
    EXPECT_EQ(removed, expected_removed.size());
  }
}

}  // namespace
}  // namespace stvl::mapping

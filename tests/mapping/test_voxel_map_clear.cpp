// The voxel map's decay models, the frustum's acceleration and both clearing modes (frustum and ray-cast),
// and the bounded walk against the full one.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>

#include "bench/synthetic_corridor.hpp"
#include "mapping/voxel_map.hpp"
#include "test_helpers.hpp"

namespace stvl::mapping {
namespace {

using test::camera_looking_along_x;
using test::cloud;
using test::wide_source;

using test::exact_config;
using test::kExactVoxel;

bool survives_single_clear(DecayModel model, double voxel_decay, double acceleration, double x, double time_s) {
  StvlConfig config = exact_config();
  config.decay_model = model;
  config.voxel_decay_s = voxel_decay;
  VoxelMap map(config);
  const auto camera = camera_looking_along_x({0, 0, 0});
  ObservationSource source = wide_source();
  source.decay_acceleration_per_s3 = acceleration;
  map.mark(cloud({{static_cast<float>(x), 0.01f, 0.01f}}), camera, source, 0.0);
  map.clear({{camera, source, nullptr}}, time_s);
  return map.lookup({x, 0.01, 0.01}).has_value();
}

double bisect(const std::function<double(double)>& f, double lo, double hi) {
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (f(lo) > 0) == (f(mid) > 0) ? lo = mid : hi = mid;
  }
  return 0.5 * (lo + hi);
}

constexpr double kInside = 2.0;    // in front of the camera
constexpr double kOutside = -2.0;  // behind it
constexpr double kEps = 1e-3;

TEST(VoxelMapDecay, LinearExpiresAtVoxelDecay) {
  EXPECT_TRUE(survives_single_clear(DecayModel::kLinear, 2.0, 0.0, kOutside, 2.0 - kEps));
  EXPECT_TRUE(survives_single_clear(DecayModel::kLinear, 2.0, 0.0, kOutside, 2.0));  // time left 0 is not < 0
  EXPECT_FALSE(survives_single_clear(DecayModel::kLinear, 2.0, 0.0, kOutside, 2.0 + kEps));
  // inside: 2 - t - 3 t^3 / 6 < 0
  const double t = bisect([](double s) { return 2.0 - s - 3.0 * s * s * s / 6.0; }, 0.0, 2.0);
  EXPECT_TRUE(survives_single_clear(DecayModel::kLinear, 2.0, 3.0, kInside, t - kEps));
  EXPECT_FALSE(survives_single_clear(DecayModel::kLinear, 2.0, 3.0, kInside, t + kEps));
}

TEST(VoxelMapDecay, ExponentialOnlyExpiresInsideFrustum) {
  EXPECT_TRUE(survives_single_clear(DecayModel::kExponential, 1.0, 6.0, kOutside, 1000.0));
  const double t = bisect([](double s) { return std::exp(-s) - s * s * s; }, 0.0, 2.0);
  EXPECT_TRUE(survives_single_clear(DecayModel::kExponential, 1.0, 6.0, kInside, t - kEps));
  EXPECT_FALSE(survives_single_clear(DecayModel::kExponential, 1.0, 6.0, kInside, t + kEps));
}

TEST(VoxelMapDecay, PersistentOnlyExpiresInsideFrustum) {
  EXPECT_TRUE(survives_single_clear(DecayModel::kPersistent, 1.0, 6.0, kOutside, 1e6));
  EXPECT_TRUE(survives_single_clear(DecayModel::kPersistent, 1.0, 0.0, kInside, 1e6));
  const double t = std::cbrt(6.0 * 1.0 / 6.0);
  EXPECT_TRUE(survives_single_clear(DecayModel::kPersistent, 1.0, 6.0, kInside, t - kEps));
  EXPECT_FALSE(survives_single_clear(DecayModel::kPersistent, 1.0, 6.0, kInside, t + kEps));
}

TEST(VoxelMapDecay, AccelerationClearsInsideBeforeOutside) {
  StvlConfig config = exact_config();
  config.voxel_decay_s = 10.0;
  VoxelMap map(config);
  const auto camera = camera_looking_along_x({0, 0, 0});
  ObservationSource source = wide_source();
  source.decay_acceleration_per_s3 = 100.0;
  map.mark(cloud({{2.0f, 0.0f, 0.0f}, {-2.0f, 0.0f, 0.0f}, {2.0f, 5.0f, 0.0f}}), camera, source, 0.0);
  map.clear({{camera, source, nullptr}}, 1.5);
  EXPECT_FALSE(map.lookup({2.0, 0.0, 0.0}).has_value());
  EXPECT_TRUE(map.lookup({-2.0, 0.0, 0.0}).has_value());  // behind
  EXPECT_TRUE(map.lookup({2.0, 5.0, 0.0}).has_value());   // beside, outside the FOV
  // STVL pulls a surviving voxel's mark back by the acceleration term.
  VoxelMap slow(config);
  source.decay_acceleration_per_s3 = 6.0;
  slow.mark(cloud({{2.0f, 0.0f, 0.0f}}), camera, source, 0.0);
  slow.clear({{camera, source, nullptr}}, 1.0);
  EXPECT_DOUBLE_EQ(*slow.lookup({2.0, 0.0, 0.0}), -1.0);
}

TEST(VoxelMapDecay, NonClearingSourceDoesNotAccelerate) {
  StvlConfig config = exact_config();
  VoxelMap map(config);
  const auto camera = camera_looking_along_x({0, 0, 0});
  ObservationSource source = wide_source();
  source.decay_acceleration_per_s3 = 100.0;
  source.clearing = false;
  map.mark(cloud({{2.0f, 0.0f, 0.0f}}), camera, source, 0.0);
  map.clear({{camera, source, nullptr}}, 1.5);
  EXPECT_EQ(map.size(), 1u);
}

// Obstacle at x = 2 seen at t = 0, then gone: the camera sees the wall at x = 4 through where it stood.
VoxelMap moved_obstacle_map(ClearingMode mode, int updates) {
  StvlConfig config = exact_config();
  config.clearing_mode = mode;
  VoxelMap map(config);
  const auto camera = camera_looking_along_x({0, 0, 0});
  ObservationSource source = wide_source();
  source.decay_acceleration_per_s3 = 20.0;
  std::vector<Eigen::Vector3f> obstacle, wall;
  for (float y = -0.5f; y <= 0.5f; y += 0.1f)
    for (float z = -0.3f; z <= 0.3f; z += 0.1f) {
      obstacle.emplace_back(2.0f, y, z);
      wall.emplace_back(4.0f, y, z);
    }
  const Eigen::Matrix3Xf obstacle_W = cloud(obstacle), wall_W = cloud(wall);
  map.clear({{camera, source, &obstacle_W}}, 0.0);
  map.mark(obstacle_W, camera, source, 0.0);
  for (int i = 1; i <= updates; ++i) {
    const double t = 0.1 * i;
    map.clear({{camera, source, &wall_W}}, t);
    map.mark(wall_W, camera, source, t);
  }
  return map;
}

TEST(VoxelMapClear, MovedObstacleClearedByFrustumAcceleration) {
  const VoxelMap early = moved_obstacle_map(ClearingMode::kFrustum, 1);
  EXPECT_TRUE(early.lookup({2.0, 0.0, 0.0}).has_value());  // 15 - 0.1 - 20*0.001/6 > 0: still there
  const VoxelMap later = moved_obstacle_map(ClearingMode::kFrustum, 10);
  EXPECT_FALSE(later.lookup({2.0, 0.0, 0.0}).has_value());
  EXPECT_FALSE(later.lookup({2.0, 0.3, 0.2}).has_value());
  // The wall is re-marked every update: age 0 means no acceleration.
  EXPECT_TRUE(later.lookup({4.0, 0.0, 0.0}).has_value());
}

TEST(VoxelMapClear, MovedObstacleClearedByRaycastAtOnce) {
  const VoxelMap map = moved_obstacle_map(ClearingMode::kRaycast, 1);
  EXPECT_FALSE(map.lookup({2.0, 0.0, 0.0}).has_value());
  EXPECT_TRUE(map.lookup({4.0, 0.0, 0.0}).has_value());
}

// Rays are walked in parallel and cleared after: the result must not depend on the number of threads.
TEST(VoxelMapClear, RaycastSameMapForAnyThreadCount) {
  auto run = [](int threads, ClearStats& stats) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    StvlConfig config;
    config.voxel_size_m = 0.05;
    config.clearing_mode = ClearingMode::kRaycast;
    VoxelMap map(config);
    std::mt19937 rng(3);
    std::uniform_int_distribution<int> kx(10, 80), ky(-30, 30), kz(-20, 20);
    std::vector<Voxel> prefill;
    for (int i = 0; i < 20000; ++i) prefill.push_back({{kx(rng), ky(rng), kz(rng)}, 0.0});
    map.set_voxels(prefill);
    std::uniform_real_distribution<float> ex(3.0f, 6.0f), ey(-2.0f, 2.0f), ez(-1.5f, 1.5f);
    std::vector<Eigen::Vector3f> ends;
    for (int i = 0; i < 8000; ++i) ends.emplace_back(ex(rng), ey(rng), ez(rng));
    const Eigen::Matrix3Xf ends_W = cloud(ends);
    stats = map.clear({{camera_looking_along_x({0.01, 0.02, 0.03}), wide_source(), &ends_W}}, 0.1);
    return map.voxels();
  };
  ClearStats serial, parallel;
  const std::vector<Voxel> one = run(1, serial), many = run(4, parallel);
  EXPECT_TRUE(test::same_voxels(one, many));
  EXPECT_EQ(serial.voxels_removed, parallel.voxels_removed);
  EXPECT_EQ(serial.voxels_visited, parallel.voxels_visited);
  EXPECT_GT(serial.voxels_removed, 1000u);  // the rays did clear, and left the rest
  EXPECT_GT(one.size(), 5000u);
}

TEST(VoxelMapClear, RaycastStopsBeforeHitVoxelInAnyDirection) {
  StvlConfig config = exact_config();
  config.clearing_mode = ClearingMode::kRaycast;
  ObservationSource source = wide_source();
  const auto camera = camera_looking_along_x({0.01, 0.02, 0.03});
  for (const Eigen::Vector3f& target :
       {Eigen::Vector3f(3, 1, -0.5), Eigen::Vector3f(-3, -2, 1), Eigen::Vector3f(0.01f, -4, 0.03f)}) {
    VoxelMap map(config);
    const Eigen::Vector3f origin = camera.translation().cast<float>();
    std::vector<Eigen::Vector3f> on_ray;
    for (float f = 0.1f; f < 0.95f; f += 0.1f) on_ray.push_back(origin + f * (target - origin));
    on_ray.push_back(target);
    map.set_voxels([&] {
      std::vector<Voxel> voxels;
      for (const auto& p : on_ray) voxels.push_back({map.key_of(p.cast<double>()), 0.0});
      voxels.push_back({map.key_of(Eigen::Vector3d(0, 3, 3)), 0.0});  // off the ray
      return voxels;
    }());
    const Eigen::Matrix3Xf hit = cloud({target});
    map.clear({{camera, source, &hit}}, 0.5);
    EXPECT_EQ(map.size(), 2u) << target.transpose();
    EXPECT_TRUE(map.lookup(target.cast<double>()).has_value());
    EXPECT_TRUE(map.lookup({0, 3, 3}).has_value());
  }
}

TEST(VoxelMapClear, RaycastRespectsMaxZ) {
  StvlConfig config = exact_config();
  config.clearing_mode = ClearingMode::kRaycast;
  VoxelMap map(config);
  ObservationSource source = wide_source();
  source.max_z_m = 2.0;
  const auto camera = camera_looking_along_x({0, 0, 0});
  map.set_voxels({{map.key_of({1.0, 0.01, 0.01}), 0.0}, {map.key_of({3.0, 0.01, 0.01}), 0.0}});
  const Eigen::Matrix3Xf hit = cloud({{5.0f, 0.01f, 0.01f}});
  map.clear({{camera, source, &hit}}, 0.1);
  EXPECT_FALSE(map.lookup({1.0, 0.01, 0.01}).has_value());
  EXPECT_TRUE(map.lookup({3.0, 0.01, 0.01}).has_value());
}

// Random voxels with random mark times, a moving camera, mark + clear per update; the bounded walk with a
// tiny expiry budget must equal the full walk once its backlog is worked off.
TEST(VoxelMapClear, BoundedWalkEqualsFullWalkAfterSweepBound) {
  for (ClearingMode mode : {ClearingMode::kFrustum, ClearingMode::kRaycast}) {
    StvlConfig config = exact_config();
    config.voxel_decay_s = 3.0;
    config.expiry_leaves_per_update = 2;
    config.clearing_mode = mode;
    VoxelMap bounded(config);
    config.clearing_walk = ClearingWalk::kFullWalk;
    VoxelMap full(config);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> coord(-6.0, 6.0), age(0.0, 4.0);
    std::vector<Voxel> seed;
    for (int i = 0; i < 3000; ++i)
      seed.push_back({bounded.key_of({coord(rng), coord(rng), coord(rng) / 3}), 2.0 - age(rng)});
    bounded.set_voxels(seed);
    full.set_voxels(seed);
    ObservationSource source = wide_source();
    source.decay_acceleration_per_s3 = 2.0;
    source.max_z_m = 5.0;
    std::size_t last_backlog = 0;
    for (int frame = 0; frame < 20; ++frame) {
      const double t = 2.0 + 0.1 * frame;
      const auto camera = camera_looking_along_x({-4.0 + 0.3 * frame, 0.0, 0.0}, 0.2 * frame);
      std::vector<Eigen::Vector3f> points;
      for (int i = 0; i < 200; ++i)
        points.emplace_back(camera.translation().cast<float>() +
                            Eigen::Vector3f(coord(rng), coord(rng), coord(rng) / 3));
      const Eigen::Matrix3Xf points_W = cloud(points);
      last_backlog = bounded.clear({{camera, source, &points_W}}, t).expiry_backlog;
      full.clear({{camera, source, &points_W}}, t);
      bounded.mark(points_W, camera, source, t);
      full.mark(points_W, camera, source, t);
      // Lag only ever keeps expired voxels: the bounded map is a superset of the full walk's.
      EXPECT_LE(full.size(), bounded.size());
    }
    EXPECT_GT(last_backlog, 0u) << "the test should exercise the bounded lag";
    const double t_end = 2.0 + 0.1 * 19;
    std::size_t extra_updates = 0;
    while (bounded.clear({}, t_end).expiry_backlog > 0) ++extra_updates;
    full.clear({}, t_end);
    EXPECT_LE(extra_updates, last_backlog / config.expiry_leaves_per_update + 1);
    EXPECT_TRUE(test::same_voxels(bounded.voxels(), full.voxels())) << to_string(mode);
  }
}

TEST(VoxelMapClear, FrustumPassVisitsOnlyNearbyLeaves) {
  VoxelMap map(exact_config());
  std::vector<Voxel> far;
  for (int i = 0; i < 64; ++i)
    for (int j = 0; j < 64; ++j) far.push_back({VoxelKey{-400 + i, j, 0}, 1.0});
  map.set_voxels(far);
  ObservationSource source = wide_source();
  source.max_z_m = 3.0;
  const auto stats = map.clear({{camera_looking_along_x({0, 0, 0}), source, nullptr}}, 1.5);
  EXPECT_EQ(stats.voxels_visited, 0u);
  EXPECT_EQ(map.size(), far.size());
}

}  // namespace
}  // namespace stvl::mapping

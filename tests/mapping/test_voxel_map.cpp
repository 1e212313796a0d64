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

TEST(VoxelMapMark, KeysAtBoundariesAndNegativeCoordinates) {
  VoxelMap map(exact_config());
  const auto camera = camera_looking_along_x({-5, 0, 0});
  map.mark(cloud({{0.125f, 0.1249f, -0.0001f}, {-0.125f, -0.1251f, 0.25f}}), camera, wide_source(), 1.0);
  ASSERT_EQ(map.size(), 2u);
  const auto keys = map.voxel_keys();
  EXPECT_EQ(keys[0], (VoxelKey{-1, -2, 2}));
  EXPECT_EQ(keys[1], (VoxelKey{1, 0, -1}));
  EXPECT_EQ(map.key_of({-1e-9, 0.0, 0.0}), (VoxelKey{-1, 0, 0}));
  EXPECT_TRUE(map.center_of({-1, 0, 0}).isApprox(Eigen::Vector3d(-0.0625, 0.0625, 0.0625)));

  EXPECT_EQ(map.lookup({0.125, 0.0, -0.125}), 1.0);  // lower corner belongs to the voxel
  EXPECT_EQ(map.lookup({0.2499, 0.1249, -1e-6}), 1.0);
  EXPECT_FALSE(map.lookup({0.25, 0.0, -0.1}).has_value());  // upper face belongs to the next voxel
  EXPECT_FALSE(map.lookup({0.1249, 0.0, -0.1}).has_value());
  EXPECT_EQ(map.lookup({-0.1, -0.2, 0.3}), 1.0);
  EXPECT_FALSE(map.lookup({std::nan(""), 0, 0}).has_value());

  const Eigen::Matrix3Xf centres = map.voxel_centers();
  ASSERT_EQ(centres.cols(), 2);
  EXPECT_TRUE(centres.col(0).isApprox(Eigen::Vector3f(-0.0625f, -0.1875f, 0.3125f)));
}

TEST(VoxelMapErase, RemovesThePresentKeysOnlyAndReportsThem) {
  VoxelMap map(StvlConfig{});
  map.set_voxels({{{0, 0, 0}, 1.0}, {{1, 0, 0}, 1.0}, {{-3, 2, 5}, 2.0}});
  std::vector<VoxelKey> erased = {{9, 9, 9}};  // appended to
  EXPECT_EQ(map.erase({{1, 0, 0}, {7, 7, 7}, {-3, 2, 5}, {1, 0, 0}}, &erased), 2u);
  EXPECT_EQ(map.size(), 1u);
  EXPECT_TRUE(map.contains({0, 0, 0}));
  EXPECT_FALSE(map.contains({1, 0, 0}));
  ASSERT_EQ(erased.size(), 3u);
  EXPECT_EQ(erased[1], (VoxelKey{1, 0, 0}));
  EXPECT_EQ(erased[2], (VoxelKey{-3, 2, 5}));
  EXPECT_EQ(map.erase({}), 0u);
  // Marking again after an erase works as on an empty voxel.
  map.set_voxels({{{1, 0, 0}, 3.0}});
  EXPECT_EQ(map.size(), 2u);
}

TEST(VoxelMapKeys, ForEachKeyInVisitsExactlyTheVoxelsInsideTheBox) {
  VoxelMap map;
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> coord(-40, 40);
  std::vector<Voxel> voxels;
  for (int i = 0; i < 3000; ++i) voxels.push_back({{coord(rng), coord(rng), coord(rng)}, 1.0});
  map.set_voxels(voxels);
  const VoxelKey lo{-9, -3, 0}, hi{17, 8, 30};  // not aligned to the 8^3 leaves
  std::vector<VoxelKey> visited, expected;
  map.for_each_key_in(lo, hi, [&](const VoxelKey& k) { visited.push_back(k); });
  for (const auto& k : map.voxel_keys())
    if (k.x >= lo.x && k.x <= hi.x && k.y >= lo.y && k.y <= hi.y && k.z >= lo.z && k.z <= hi.z) expected.push_back(k);
  std::sort(visited.begin(), visited.end());
  ASSERT_GT(expected.size(), 20u);
  EXPECT_EQ(visited, expected);
  std::size_t none = 0;
  map.for_each_key_in(hi, lo, [&](const VoxelKey&) { ++none; });  // an empty box
  EXPECT_EQ(none, 0u);
}

TEST(VoxelMapMark, SkipsOutOfRangeOutOfBandNonFiniteAndSensorOrigin) {
  VoxelMap map(exact_config());
  ObservationSource source = wide_source();
  source.obstacle_range_m = 2.0;
  source.min_obstacle_height_m = 0.0;
  source.max_obstacle_height_m = 1.0;
  const auto camera = camera_looking_along_x({0, 0, 0.5});
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const std::size_t marked = map.mark(cloud({
                                          {1.0f, 0.0f, 0.5f},    // kept
                                          {2.4f, 0.0f, 0.5f},    // beyond range
                                          {1.0f, 0.0f, -0.01f},  // below band
                                          {1.0f, 0.0f, 1.01f},   // above band
                                          {1.0f, 0.0f, 1.0f},    // on the band's edge: kept
                                          {nan, 0.0f, 0.5f},
                                          {1.0f, inf, 0.5f},
                                          {0.0f, 0.0f, 0.5f},  // at the sensor
                                      }),
                                      camera, source, 3.0);
  EXPECT_EQ(marked, 2u);
  EXPECT_EQ(map.size(), 2u);
  EXPECT_TRUE(map.lookup({1.0, 0.0, 0.5}).has_value());
  EXPECT_TRUE(map.lookup({1.0, 0.0, 1.0}).has_value());
  // STVL's filter none: no band, every height marks (still within range).
  source.height_band = false;
  EXPECT_EQ(map.mark(cloud({{1.0f, 0.0f, -0.25f}, {1.0f, 0.0f, 1.25f}, {2.4f, 0.0f, 0.5f}}), camera, source, 3.0), 2u);
  EXPECT_EQ(map.size(), 4u);
  source.marking = false;
  EXPECT_EQ(map.mark(cloud({{1.5f, 0.0f, 0.5f}}), camera, source, 3.0), 0u);
  EXPECT_EQ(map.size(), 4u);
}

// One voxel at (x, 0, 0) marked at t = 0, cleared once at time_s by a camera at the origin looking along +x.
TEST(VoxelMap, DeterministicForSameInputs) {
  auto run = [] {
    StvlConfig config;
    config.expiry_leaves_per_update = 3;
    VoxelMap map(config);
    ObservationSource source = wide_source();
    source.decay_acceleration_per_s3 = 1.0;
    for (int f = 0; f < 8; ++f) {
      const bench::SyntheticFrame frame = bench::synthetic_corridor_frame(3, f, 0.05);
      map.clear({{frame.T_world_camera, source, &frame.points_W}}, frame.time_s);
      map.mark(frame.points_W, frame.T_world_camera, source, frame.time_s);
    }
    return map.voxels();
  };
  const auto a = run(), b = run();
  EXPECT_GT(a.size(), 1000u);
  EXPECT_TRUE(test::same_voxels(a, b));
  const auto f1 = bench::synthetic_corridor_frame(3, 2, 0.05), f2 = bench::synthetic_corridor_frame(3, 2, 0.05);
  EXPECT_TRUE(f1.points_W.isApprox(f2.points_W));
}

TEST(VoxelMapErrors, BadParametersNameTheField) {
  auto expect_message = [](auto&& make, const std::string& field) {
    try {
      make();
      ADD_FAILURE() << "no exception for " << field;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  auto with_config = [](auto edit) {
    return [edit] {
      StvlConfig config;
      edit(config);
      VoxelMap map(config);
    };
  };
  expect_message(with_config([](StvlConfig& c) { c.voxel_size_m = 0.0; }), "voxel_size");
  expect_message(with_config([](StvlConfig& c) { c.voxel_size_m = -0.05; }), "voxel_size");
  expect_message(with_config([](StvlConfig& c) { c.voxel_size_m = std::nan(""); }), "voxel_size");
  expect_message(with_config([](StvlConfig& c) { c.voxel_size_m = 0.001; }), "voxel_size");
  expect_message(with_config([](StvlConfig& c) { c.voxel_size_m = 2.0; }), "voxel_size");
  expect_message(with_config([](StvlConfig& c) { c.voxel_decay_s = -1.0; }), "voxel_decay");
  expect_message(with_config([](StvlConfig& c) { c.mark_threshold = -1; }), "mark_threshold");
  expect_message(with_config([](StvlConfig& c) { c.expiry_leaves_per_update = 0; }), "expiry_leaves_per_update");
  expect_message([] { parse_decay_model("3"); }, "decay_model");
  expect_message([] { parse_clearing_mode("lidar"); }, "clearing_mode");
  EXPECT_EQ(parse_decay_model("-1"), DecayModel::kPersistent);
  EXPECT_EQ(parse_decay_model("2"), DecayModel::kPersistent);
  EXPECT_EQ(parse_decay_model("exponential"), DecayModel::kExponential);
  EXPECT_EQ(parse_decay_model("0"), DecayModel::kLinear);

  VoxelMap map;
  const auto camera = camera_looking_along_x({0, 0, 0});
  const Eigen::Matrix3Xf points = cloud({{1, 0, 0}});
  auto with_source = [&](auto edit) {
    return [&, edit] {
      ObservationSource source = wide_source();
      edit(source);
      map.mark(points, camera, source, 1.0);
    };
  };
  expect_message(with_source([](ObservationSource& s) { s.horizontal_fov_rad = 0.0; }), "horizontal_fov_angle");
  expect_message(with_source([](ObservationSource& s) { s.horizontal_fov_rad = 3.2; }), "horizontal_fov_angle");
  expect_message(with_source([](ObservationSource& s) { s.vertical_fov_rad = -1.0; }), "vertical_fov_angle");
  expect_message(with_source([](ObservationSource& s) {
                   s.min_z_m = 5.0;
                   s.max_z_m = 5.0;
                 }),
                 "min_z");
  expect_message(with_source([](ObservationSource& s) { s.min_z_m = -0.1; }), "min_z");
  expect_message(with_source([](ObservationSource& s) { s.max_z_m = std::numeric_limits<double>::infinity(); }),
                 "max_z");
  expect_message(with_source([](ObservationSource& s) { s.decay_acceleration_per_s3 = -1.0; }), "decay_acceleration");
  expect_message(with_source([](ObservationSource& s) { s.obstacle_range_m = 0.0; }), "obstacle_range");
  expect_message(with_source([](ObservationSource& s) {
                   s.min_obstacle_height_m = 2.0;
                   s.max_obstacle_height_m = 1.0;
                 }),
                 "min_obstacle_height");

  Eigen::Isometry3d bad_pose = camera;
  bad_pose.translation().x() = std::nan("");
  expect_message([&] { map.mark(points, bad_pose, wide_source(), 1.0); }, "T_world_camera");
  bad_pose = camera;
  bad_pose.linear() *= 2.0;
  expect_message([&] { map.mark(points, bad_pose, wide_source(), 1.0); }, "T_world_camera");
  map.mark(points, camera, wide_source(), 5.0);
  expect_message([&] { map.mark(points, camera, wide_source(), 4.0); }, "time_s");
  expect_message([&] { map.clear({}, std::nan("")); }, "time_s");

  StvlConfig raycast;
  raycast.clearing_mode = ClearingMode::kRaycast;
  VoxelMap ray_map(raycast);
  expect_message([&] { ray_map.clear({{camera, wide_source(), nullptr}}, 1.0); }, "points_W");
  ObservationSource no_return = wide_source();
  no_return.clear_on_no_return = true;
  expect_message(
      [&] {
        map.clear({{camera, no_return, &points}}, 6.0);
      },
      "clear_on_no_return needs clearing_mode = raycast");
}

// clear_on_no_return: the ray of a pixel that returned nothing clears what it passes up to max_z, and the
// voxels it removed are reported; without the option (STVL) it clears nothing.
TEST(VoxelMap, NoReturnRaysClearOnlyWithTheOption) {
  StvlConfig config;
  config.clearing_mode = ClearingMode::kRaycast;
  const Eigen::Isometry3d camera = test::camera_looking_along_x({0.0, 0.0, 0.5});
  const Eigen::Matrix3Xf none(3, 0);
  const Eigen::Matrix3Xf far_end = test::cloud({{5.0f, 0.0f, 0.5f}});      // a no-return ray's point at max_z = 5 m
  const std::vector<Voxel> stale{{{40, 0, 10}, 0.5}, {{60, 0, 10}, 0.5}};  // 2.0 m and 3.0 m along the ray
  for (const bool option : {false, true}) {
    SCOPED_TRACE(option);
    VoxelMap map(config);
    map.set_voxels(stale);
    ObservationSource source = test::wide_source();
    source.max_z_m = 5.0;
    source.clear_on_no_return = option;
    ClearingObservation observation{camera, source, &none};
    observation.no_return_W = &far_end;
    std::vector<VoxelKey> cleared;
    const ClearStats stats = map.clear({observation}, 1.0, &cleared);
    EXPECT_EQ(map.size(), option ? 0u : 2u);
    EXPECT_EQ(stats.voxels_removed, option ? 2u : 0u);
    std::sort(cleared.begin(), cleared.end());
    const std::vector<VoxelKey> expected =
        option ? std::vector<VoxelKey>{{40, 0, 10}, {60, 0, 10}} : std::vector<VoxelKey>{};
    EXPECT_EQ(cleared, expected);
  }
}

// Frustum mode reports in cleared_keys the voxels the frustum's acceleration removed (those plain decay would have
// kept), never those that expired by plain decay, inside the frustum or outside it; in both walks.
TEST(VoxelMapClear, FrustumReportsOnlyWhatItsAccelerationRemoved) {
  for (const ClearingWalk walk : {ClearingWalk::kBounded, ClearingWalk::kFullWalk}) {
    SCOPED_TRACE(to_string(walk));
    StvlConfig config = exact_config();
    config.voxel_decay_s = 10.0;
    config.clearing_walk = walk;
    VoxelMap map(config);
    const auto camera = camera_looking_along_x({0, 0, 0});
    ObservationSource source = wide_source();
    source.decay_acceleration_per_s3 = 100.0;
    const VoxelKey accelerated = map.key_of({2.0, 0.0, 0.0});      // age 1.5: 8.5 s left, 100 * 1.5^3 / 6 = 56 s taken
    const VoxelKey expired_inside = map.key_of({3.0, 0.0, 0.0});   // age 21.5: plain decay removes it
    const VoxelKey expired_behind = map.key_of({-2.0, 0.0, 0.0});  // outside the frustum, age 21.5
    const VoxelKey fresh = map.key_of({2.5, 0.0, 0.0});            // age 0.1: 0.017 s taken, survives
    const VoxelKey beside = map.key_of({2.0, 5.0, 0.0});           // outside the FOV, age 1.5: kept
    map.set_voxels({{accelerated, 0.0}, {expired_inside, -20.0}, {expired_behind, -20.0}, {fresh, 1.4}, {beside, 0.0}});
    std::vector<VoxelKey> cleared;
    const ClearStats stats = map.clear({{camera, source, nullptr}}, 1.5, &cleared);
    EXPECT_EQ(stats.voxels_removed, 3u);
    EXPECT_EQ(cleared, std::vector<VoxelKey>{accelerated});
    EXPECT_TRUE(map.contains(fresh));
    EXPECT_TRUE(map.contains(beside));
    EXPECT_EQ(map.size(), 2u);
    // No acceleration, nothing reported: the same map empties by plain decay alone.
    source.decay_acceleration_per_s3 = 0.0;
    cleared.clear();
    map.clear({{camera, source, nullptr}}, 100.0, &cleared);
    EXPECT_TRUE(map.empty());
    EXPECT_TRUE(cleared.empty());
  }
}

TEST(VoxelMap, LeafMasksHoldTheSameVoxelsAsForEachKey) {
  VoxelMap map(exact_config());
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> coord(-20, 20);
  std::vector<Voxel> voxels;
  for (int i = 0; i < 3000; ++i) voxels.push_back({{coord(rng), coord(rng), coord(rng)}, 1.0});
  map.set_voxels(voxels);
  std::vector<VoxelKey> removed;  // a few voxels, and every voxel of the leaves with x keys -16..-9
  for (int i = 0; i < 1500; ++i) removed.push_back({coord(rng), coord(rng), coord(rng)});
  for (const auto& k : map.voxel_keys())
    if (k.x >= -16 && k.x <= -9) removed.push_back(k);
  map.erase(removed);
  std::vector<VoxelKey> from_masks, from_keys;
  map.for_each_leaf([&](const VoxelKey& origin, const std::uint64_t* on) {
    EXPECT_TRUE(origin.x % 8 == 0 && origin.y % 8 == 0 && origin.z % 8 == 0);
    for (int i = 0; i < 512; ++i)
      if ((on[i / 64] >> (i % 64)) & 1u)
        from_masks.push_back({origin.x + (i >> 6), origin.y + ((i >> 3) & 7), origin.z + (i & 7)});
  });
  map.for_each_key([&](const VoxelKey& k) { from_keys.push_back(k); });
  std::sort(from_masks.begin(), from_masks.end());
  std::sort(from_keys.begin(), from_keys.end());
  EXPECT_GT(from_keys.size(), 1000u);
  EXPECT_EQ(from_masks, from_keys);
}

}  // namespace
}  // namespace stvl::mapping

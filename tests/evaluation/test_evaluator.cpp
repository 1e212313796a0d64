// The Evaluator on the fixture's tiny box-and-cart world: a box whose front face the camera sees head-on, and a
// mocap cart that moves away. Depth images are drawn analytically, so the expected figures follow from the geometry.
#include "evaluation/evaluator.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "tests/evaluation/box_face.hpp"
#include "tests/support/fixture.hpp"

namespace stvl::evaluation {
namespace {

// The box's front face (x = 2.05) lies in voxel layer x = 20 at 0.1 m: 6 x 6 surface voxels (box_face.hpp).
constexpr const char* kWorld = stvl::test::kBoxAndCartWorld;
constexpr double kFaceX = 2.05;

EvaluationConfig config() { return test::config_at_0p1(0); }  // a mapped voxel matches only itself

// Camera at (0, 0, 0.4) looking along +x: optical z = world x, optical x = -y, optical y = -z.
CameraView camera_view(const sensors::DepthImage& depth, const sensors::CameraIntrinsics& k) {
  CameraView view;
  view.clean_depth = &depth;
  view.intrinsics = k;
  view.T_world_camera = stvl::test::looking_along_x({0, 0, 0.4});
  view.obstacle_range_m = 10.0;
  return view;
}

sensors::CameraIntrinsics intrinsics() {
  sensors::CameraIntrinsics k;
  k.width = 200, k.height = 160, k.fx = k.fy = 100.0, k.cx = 99.5, k.cy = 79.5;
  return k;
}

// What the camera sees of the box's front face (2 cm between pixels there); 0 elsewhere (no return).
sensors::DepthImage face_depth(const sensors::CameraIntrinsics& k) {
  sensors::DepthImage image(k.width, k.height);
  for (int v = 0; v < k.height; ++v)
    for (int u = 0; u < k.width; ++u) {
      const double y_W = -(u - k.cx) / k.fx * kFaceX, z_W = 0.4 - (v - k.cy) / k.fy * kFaceX;
      if (std::abs(y_W) < 0.25 && z_W > 0.15 && z_W < 0.65) image.at(u, v) = static_cast<float>(kFaceX);
    }
  return image;
}

std::vector<VoxelKey> face_voxels() { return test::box_face_voxels(); }

mapping::VoxelMap map_with(const std::vector<VoxelKey>& keys) { return test::map_with(keys, 0.5); }

ObstacleResult obstacle(const EvaluationSummary& s, const std::string& name) {
  for (const auto& o : s.obstacles)
    if (o.name == name) return o;
  ADD_FAILURE() << "no obstacle " << name;
  return {};
}

TEST(Evaluator, ObservedFaceVoxelsAreRecallsDenominator) {
  const sim::World world = sim::World::from_string(kWorld);
  Evaluator evaluator(world, config());
  const auto k = intrinsics();
  const sensors::DepthImage depth = face_depth(k);
  evaluator.observe(1.0, camera_view(depth, k));
  const auto all = face_voxels();
  const EvaluationSnapshot& snap = evaluator.evaluate(1.0, world, map_with(all));
  EXPECT_EQ(snap.observed_truth_voxels, all.size());
  EXPECT_EQ(snap.matched_truth, all.size());
  EXPECT_DOUBLE_EQ(snap.recall, 1.0);
  EXPECT_DOUBLE_EQ(snap.precision, 1.0);
}

TEST(Evaluator, OneFalseVoxelAmongNMappedGivesPrecisionNMinusOneOverN) {
  const sim::World world = sim::World::from_string(kWorld);
  Evaluator evaluator(world, config());
  std::vector<VoxelKey> mapped = face_voxels();
  mapped.resize(18);
  mapped.push_back({0, 30, 5});  // 3 m beside everything: false
  const EvaluationSnapshot& snap = evaluator.evaluate(1.0, world, map_with(mapped));
  EXPECT_EQ(snap.mapped_voxels, 19u);
  EXPECT_DOUBLE_EQ(snap.precision, 18.0 / 19.0);
}

TEST(Evaluator, AnObstacleWithHalfOfItsObservedVoxelsMappedIsDetectedAndOneWithFewerIsNot) {
  const auto k = intrinsics();
  const sensors::DepthImage depth = face_depth(k);
  for (const std::size_t mapped : {18u, 17u}) {  // of 36 observed
    const sim::World world = sim::World::from_string(kWorld);
    Evaluator evaluator(world, config());
    evaluator.observe(1.0, camera_view(depth, k));
    std::vector<VoxelKey> keys = face_voxels();
    keys.resize(mapped);
    const mapping::VoxelMap map = map_with(keys);
    evaluator.evaluate(1.0, world, map);
    const EvaluationSummary summary = evaluator.finish(1.0, world, map);
    const ObstacleResult box = obstacle(summary, "box");
    EXPECT_TRUE(box.observed);
    EXPECT_EQ(box.observed_voxels, 36u);
    EXPECT_DOUBLE_EQ(box.best_recall, mapped / 36.0);
    EXPECT_EQ(box.detected, mapped == 18u) << mapped << " of 36";
    EXPECT_FALSE(obstacle(summary, "cart").observed);
  }
}

TEST(Evaluator, StaleVoxelSeenThroughAtT0AndRemovedAtT1HasLatencyT1MinusT0) {
  sim::World world = sim::World::from_string(kWorld);
  Evaluator evaluator(world, config());                                 // the cart at its first place
  world.data()->mocap_pos[0] = -5.0, world.data()->mocap_pos[1] = 3.0;  // then it leaves
  world.forward();
  const auto k = intrinsics();
  sensors::DepthImage depth = face_depth(k);
  // Two voxels of the cart's old place are still in the map. Behind (10, 0, 4) (pixel 95, 75) the camera sees
  // the box 1 m farther: seen through. Behind (9, -1, 3) (pixel 105, 85) it has no return: not seen through.
  const VoxelKey seen{10, 0, 4}, unseen{9, -1, 3};
  for (int v = 83; v <= 87; ++v)
    for (int u = 103; u <= 107; ++u) depth.at(u, v) = 0.0f;
  const mapping::VoxelMap before = map_with({seen, unseen});
  evaluator.observe_clearing(1.0, world, camera_view(depth, k), before);
  evaluator.after_update(1.0, before);  // the update at 1.0 removed nothing
  const mapping::VoxelMap after = map_with({});
  evaluator.observe_clearing(1.4, world, camera_view(depth, k), after);
  evaluator.after_update(1.4, after);  // both gone at 1.4
  const EvaluationSummary summary = evaluator.finish(2.0, world, after);
  EXPECT_EQ(summary.clearing.stale_voxels_seen_through, 1u);  // the unseen one is neither cleared nor missed
  EXPECT_EQ(summary.clearing.not_cleared, 0u);
  EXPECT_NEAR(summary.clearing.max_latency_s, 0.4, 1e-12);
}

TEST(Evaluator, AStaleVoxelStillMappedAtTheEndIsNotCleared) {
  sim::World world = sim::World::from_string(kWorld);
  Evaluator evaluator(world, config());
  world.data()->mocap_pos[0] = -5.0;
  world.forward();
  const auto k = intrinsics();
  const sensors::DepthImage depth = face_depth(k);
  const mapping::VoxelMap map = map_with({{10, 0, 4}});
  evaluator.observe_clearing(1.0, world, camera_view(depth, k), map);
  evaluator.after_update(1.0, map);
  const EvaluationSummary summary = evaluator.finish(3.5, world, map);
  EXPECT_EQ(summary.clearing.stale_voxels_seen_through, 1u);
  EXPECT_EQ(summary.clearing.not_cleared, 1u);
  EXPECT_NEAR(summary.clearing.max_latency_s, 2.5, 1e-12);
}

TEST(Truth, ChangesVersionOnlyWhenAMovingBodyMoves) {
  sim::World world = sim::World::from_string(kWorld);
  Truth truth(world, config());
  const std::size_t first = truth.version();
  truth.update(world);
  EXPECT_EQ(truth.version(), first);
  EXPECT_TRUE(truth.near_moving({10, 0, 4}));  // the cart's voxel
  world.data()->mocap_pos[0] = -5.0;
  world.forward();
  truth.update(world);
  EXPECT_EQ(truth.version(), first + 1);
  EXPECT_FALSE(truth.near_moving({10, 0, 4}));
  for (const auto* body : truth.bodies())
    if (body->body_name == "cart") {
      ASSERT_FALSE(body->voxels.empty());
      EXPECT_LT(body->voxels.front().x, -40);  // the cart's voxels are at its new place
      EXPECT_TRUE(truth.near_moving(body->voxels.front()));
    }
  EXPECT_TRUE(truth.near_static({20, 0, 4}));   // the box's front face
  EXPECT_FALSE(truth.near_static({19, 0, 4}));  // one voxel in front of it: tolerance 0 here
  EvaluationConfig one = config();
  one.tolerance_voxels = 1;
  const Truth tolerant(world, one);
  EXPECT_TRUE(tolerant.near_static({19, 0, 4}));
  EXPECT_FALSE(tolerant.near_static({18, 0, 4}));
}

// An open bin (a box without its top, inline mesh faces) on a mocap body: x 1.01..1.59, y 0.01..0.39, z 0.01..0.49.
constexpr const char* kOpenBinWorld = R"(
<mujoco>
  <asset><mesh name="bin" vertex="0.01 0.01 0.01  0.59 0.01 0.01  0.01 0.39 0.01  0.59 0.39 0.01
                                  0.01 0.01 0.49  0.59 0.01 0.49  0.01 0.39 0.49  0.59 0.39 0.49"
               face="0 4 6  0 6 2  1 3 7  1 7 5  0 1 5  0 5 4  2 6 7  2 7 3  0 2 3  0 3 1"/></asset>
  <worldbody><body name="bin" mocap="true" pos="1 0 0"><geom name="bin_geom" type="mesh" mesh="bin"/></body></worldbody>
</mujoco>)";

TEST(Truth, MeshesAreTheirTrianglesAndAnOpenOneIsNoted) {
  sim::World world = sim::World::from_string(kOpenBinWorld);
  EvaluationConfig c = config();
  c.min_obstacle_height_m = 0.1;  // above the bin's bottom
  Truth truth(world, c);
  EXPECT_EQ(truth.geom_count(), 1u);
  EXPECT_EQ(truth.mesh_geom_count(), 1u);
  EXPECT_EQ(truth.mesh_triangle_count(), 10u);
  ASSERT_EQ(truth.notes().size(), 1u);
  EXPECT_NE(truth.notes()[0].note.find("geom 'bin_geom' (mesh 'bin', body 'bin') is not closed"), std::string::npos)
      << truth.notes()[0].note;
  // Its footprint in the band is its four walls, cells x 10..15, y 0..3 less the inside (its bounding box: 24).
  EXPECT_EQ(truth.footprint().size(), 24u - 8u);
  EXPECT_FALSE(truth.footprint().contains({12, 1}));
  EXPECT_TRUE(truth.footprint().contains({10, 1}));
  EXPECT_TRUE(truth.contains({10, 1, 3}));   // the -x wall
  EXPECT_FALSE(truth.contains({12, 1, 3}));  // inside the bin
  ASSERT_TRUE(truth.distance_to_surface_m({1.3, 0.2, 0.3}).has_value());
  EXPECT_NEAR(*truth.distance_to_surface_m({1.3, 0.2, 0.3}), 0.19, 1e-6);  // to the walls at y 0.01 and 0.39
  world.data()->mocap_pos[0] = 3.0;                                        // moved: voxelized again where it is
  world.forward();
  truth.update(world);
  EXPECT_TRUE(truth.contains({30, 1, 3}));
  EXPECT_FALSE(truth.contains({10, 1, 3}));
  EXPECT_TRUE(truth.footprint().contains({30, 1}));
}

TEST(Evaluator, BadConfigIsRejected) {
  const sim::World world = sim::World::from_string(kWorld);
  EvaluationConfig c = config();
  c.recall_window_s = 0.0;
  EXPECT_THROW(Evaluator(world, c), std::invalid_argument);
  c = config();
  c.voxel_size_m = std::nan("");
  EXPECT_THROW(Evaluator(world, c), std::invalid_argument);
}

}  // namespace
}  // namespace stvl::evaluation

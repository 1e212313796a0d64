// Occluded obstacles erased (evaluation/occlusion.hpp): what the noise-free camera saw of a voxel, the count of
// true voxels cleared unseen, and the Evaluator's wiring, on hand-made depth images, keys and a tiny world.
#include "evaluation/occlusion.hpp"

#include <gtest/gtest.h>

#include <map>
#include <set>
#include <vector>

#include "evaluation/evaluator.hpp"
#include "tests/evaluation/box_face.hpp"
#include "tests/support/fixture.hpp"

namespace stvl::evaluation {
namespace {

constexpr double kVoxel = 0.1;

sensors::CameraIntrinsics intrinsics() {
  sensors::CameraIntrinsics k;
  k.width = 200, k.height = 160, k.fx = k.fy = 100.0, k.cx = 99.5, k.cy = 79.5;
  return k;
}

using stvl::test::looking_along_x;

// Camera at the origin: a near surface at depth 1 m over the columns u < 90 (world y > ~0.2 m at x = 2 m), a
// wall at 3 m elsewhere, no return in the rows v < 20 (world z > ~1.2 m at x = 2 m).
sensors::DepthImage near_and_far(const sensors::CameraIntrinsics& k) {
  sensors::DepthImage image(k.width, k.height);
  for (int v = 20; v < k.height; ++v)
    for (int u = 0; u < k.width; ++u) image.at(u, v) = u < 90 ? 1.0f : 3.0f;
  return image;
}

VoxelSight sight_of(const VoxelKey& key) {
  static const sensors::DepthImage depth = near_and_far(intrinsics());
  return voxel_sight(key, kVoxel, depth, intrinsics(), looking_along_x({0, 0, 0}), kVoxel);
}

TEST(VoxelSight, BehindANearerSurfaceSeenOrOutOfView) {
  EXPECT_EQ(sight_of({20, 3, 0}), VoxelSight::kBehindSurface);  // x 2.0..2.1, y 0.3..0.4: behind the 1 m surface
  EXPECT_EQ(sight_of({20, -4, 0}), VoxelSight::kSeen);          // y -0.4..-0.3: the wall at 3 m lies beyond it
  // y 0.2..0.3: its centre's pixel (87) is behind the near surface, its corner (2.1, 0.2) reaches pixel 90: partly
  // seen counts as seen.
  EXPECT_EQ(sight_of({20, 2, 0}), VoxelSight::kSeen);
  EXPECT_EQ(sight_of({30, -4, 0}), VoxelSight::kSeen);           // x 3.0..3.1: the wall's own voxel (within 0.1 m)
  EXPECT_EQ(sight_of({32, -4, 0}), VoxelSight::kBehindSurface);  // x 3.2..3.3: behind the wall
  EXPECT_EQ(sight_of({-21, 0, 0}), VoxelSight::kOutOfView);      // behind the camera
  EXPECT_EQ(sight_of({20, 40, 0}), VoxelSight::kOutOfView);      // y 4 m: outside the image
  EXPECT_EQ(sight_of({20, -4, 15}), VoxelSight::kOutOfView);     // z 1.5 m: pixels without a return
}

// Hand-made truth: body 0 "box" and body 1 "wall"; what is in the map and what the camera saw are given per key.
struct Scene {
  truth::BodyVoxels box{0, "box", {{1, 0, 0}, {2, 0, 0}, {3, 0, 0}}};
  truth::BodyVoxels wall{1, "wall", {{9, 0, 0}}};
  std::vector<const truth::BodyVoxels*> bodies{&box, &wall};
  std::set<VoxelKey> in_map;
  std::map<VoxelKey, VoxelSight> sight;

  void update(HiddenClears& h, double time_s, const std::vector<VoxelKey>& cleared) const {
    h.after_update(
        time_s, cleared, bodies,
        [&](const VoxelKey& k) {
          for (std::size_t b = 0; b < bodies.size(); ++b)
            for (const VoxelKey& v : bodies[b]->voxels)
              if (v == k) return static_cast<int>(b);
          return -1;
        },
        [&](const VoxelKey& k) { return in_map.count(k) > 0; },
        [&](const VoxelKey& k) { return sight.count(k) ? sight.at(k) : VoxelSight::kSeen; });
  }
};

TEST(HiddenClears, OnlyTrueVoxelsRemovedUnseenAndNotMarkedAgainCount) {
  Scene scene;
  scene.sight = {{{1, 0, 0}, VoxelSight::kBehindSurface},
                 {{2, 0, 0}, VoxelSight::kBehindSurface},
                 {{3, 0, 0}, VoxelSight::kSeen},
                 {{9, 0, 0}, VoxelSight::kOutOfView},
                 {{5, 5, 5}, VoxelSight::kBehindSurface}};
  scene.in_map = {{2, 0, 0}};  // removed, but the same update marked it again
  HiddenClears h;
  // (1,0,0) hidden and removed: counts. (2,0,0) marked again, (3,0,0) seen, (5,5,5) no truth: none counts.
  scene.update(h, 1.0, {{1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {5, 5, 5}});
  OcclusionResult r = h.result();
  EXPECT_EQ(r.hidden_false_clears, 1u);
  EXPECT_EQ(r.behind_surface, 1u);
  EXPECT_EQ(r.out_of_view, 0u);
  ASSERT_TRUE(r.first_s.has_value());
  EXPECT_DOUBLE_EQ(*r.first_s, 1.0);
  ASSERT_EQ(r.bodies.size(), 1u);
  EXPECT_EQ(r.bodies[0].name, "box");
  EXPECT_FALSE(r.bodies[0].vanished_s.has_value());  // (2,0,0) is still in the map
  // A hidden voxel that no clearing removed does not count, whatever the map holds.
  scene.update(h, 1.5, {});
  EXPECT_EQ(h.result().hidden_false_clears, 1u);
  // The wall's voxel out of view is removed; then the box's last one, hidden: the box vanishes at 2.0.
  scene.update(h, 1.8, {{9, 0, 0}});
  scene.in_map.clear();
  scene.sight[{2, 0, 0}] = VoxelSight::kBehindSurface;
  scene.update(h, 2.0, {{2, 0, 0}});
  r = h.result();
  EXPECT_EQ(r.hidden_false_clears, 3u);
  EXPECT_EQ(r.behind_surface, 2u);
  EXPECT_EQ(r.out_of_view, 1u);
  ASSERT_EQ(r.bodies.size(), 2u);
  EXPECT_EQ(r.bodies[0].name, "box");
  EXPECT_EQ(r.bodies[0].hidden_false_clears, 2u);
  EXPECT_DOUBLE_EQ(r.bodies[0].first_s, 1.0);
  EXPECT_DOUBLE_EQ(r.bodies[0].last_s, 2.0);
  ASSERT_TRUE(r.bodies[0].vanished_s.has_value());
  EXPECT_DOUBLE_EQ(*r.bodies[0].vanished_s, 2.0);
  EXPECT_EQ(r.bodies[1].name, "wall");
  EXPECT_DOUBLE_EQ(*r.bodies[1].vanished_s, 1.8);
}

// Through the Evaluator: a box whose front face (x = 2.05, voxel layer x = 20 at 0.1 m) a cart right in front of
// the camera hides. Its face voxels were in the map; the update removed all but one.
constexpr const char* kWorld = R"(
<mujoco>
  <worldbody>
    <body name="box" pos="2.35 0 0.4"><geom type="box" size="0.3 0.25 0.25"/></body>
    <body name="cart" mocap="true" pos="0.8 0 0.4"><geom type="box" size="0.1 0.6 0.6"/></body>
  </worldbody>
</mujoco>)";

TEST(Evaluator, HiddenBoxVoxelsRemovedInEitherModeAreHiddenFalseClearsAndRaysFalseClearsStayRaysOnly) {
  const std::vector<VoxelKey> face = test::box_face_voxels();
  const auto k = intrinsics();
  sensors::DepthImage cart_depth(k.width, k.height);  // the cart's face at x = 0.7 fills the view
  for (float& z : cart_depth.depth_m) z = 0.7f;
  sensors::DepthImage clear_depth(k.width, k.height);  // the cart gone: the box's face at 2.05 m
  for (float& z : clear_depth.depth_m) z = 2.05f;
  for (const auto mode : {mapping::ClearingMode::kFrustum, mapping::ClearingMode::kRaycast}) {
    SCOPED_TRACE(mapping::to_string(mode));
    for (const bool hidden : {true, false}) {
      SCOPED_TRACE(hidden ? "hidden" : "visible");
      const sim::World world = sim::World::from_string(kWorld);
      EvaluationConfig config;
      config.voxel_size_m = kVoxel;
      config.max_obstacle_height_m = 2.0;
      Evaluator evaluator(world, config);
      mapping::StvlConfig map_config;
      map_config.voxel_size_m = kVoxel;
      map_config.clearing_mode = mode;
      mapping::VoxelMap map(map_config);
      map.set_voxels({{face.back(), 0.5}});  // the update left one face voxel
      const std::vector<VoxelKey> cleared(face.begin(), face.end() - 1);
      CameraView view;
      view.clean_depth = hidden ? &cart_depth : &clear_depth;
      view.intrinsics = k;
      view.T_world_camera = looking_along_x({0, 0, 0.4});
      evaluator.after_update(1.0, map, cleared);
      evaluator.observe_hidden_clears(1.0, view, map, cleared);
      const EvaluationSummary s = evaluator.finish(1.0, world, map);
      EXPECT_EQ(s.occlusion.hidden_false_clears, hidden ? cleared.size() : 0u);
      EXPECT_EQ(s.occlusion.behind_surface, hidden ? cleared.size() : 0u);
      EXPECT_EQ(s.occlusion.bodies.size(), hidden ? 1u : 0u);
      if (hidden) {
        EXPECT_FALSE(s.occlusion.bodies[0].vanished_s.has_value());  // one face voxel is left
      }
      // evaluation.clearing.false_clears counts the rays' removals only, as before.
      EXPECT_EQ(s.false_clears, mode == mapping::ClearingMode::kRaycast ? cleared.size() : 0u);
    }
  }
}

}  // namespace
}  // namespace stvl::evaluation

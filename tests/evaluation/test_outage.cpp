// OutageMonitor on hand-made frames: a box's face seen by two cameras, maps with voxels taken out.
#include "evaluation/outage.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "tests/evaluation/box_face.hpp"
#include "tests/support/fixture.hpp"

namespace stvl::evaluation {
namespace {

// The fixture's box: its front face (x = 2.05) is the voxel layer x = 20 at 0.1 m (y keys -3..2, z keys 1..6).
constexpr const char* kWorld = stvl::test::kBoxWorld;

EvaluationConfig config() {
  EvaluationConfig c;
  c.voxel_size_m = 0.1;
  c.max_obstacle_height_m = 2.0;
  c.tolerance_voxels = 0;
  return c;
}

std::vector<VoxelKey> face() { return test::box_face_voxels(); }
mapping::VoxelMap map_of(const std::vector<VoxelKey>& keys) { return test::map_with(keys, 0.0); }

TEST(OutageMonitor, CountsWhatOnlyTheStoppedCameraSawAndLeftTheMap) {
  const sim::World world = sim::World::from_string(kWorld);
  const Truth truth(world, config());
  const std::vector<VoxelKey> keys = face();
  ASSERT_EQ(keys.size(), 36u);
  OutageMonitor monitor({{{1.0, 2.0}}, {}}, 0);  // camera 0 out in [1, 2)
  const std::vector<VoxelKey> off_truth{{5, 5, 5}};
  monitor.observe(0, 0.5, keys, truth, 100);
  monitor.observe(0, 0.5, off_truth, truth, 100);                         // not a truth voxel: not watched
  monitor.observe(1, 0.5, {keys.begin(), keys.begin() + 6}, truth, 100);  // camera 1 saw 6 of them
  const mapping::VoxelMap full = map_of(keys);
  std::vector<VoxelKey> fewer(keys.begin() + 3, keys.end() - 4);  // 3 seen by both and 4 of camera 0's alone gone
  const mapping::VoxelMap less = map_of(fewer);
  monitor.before_update(0.9, full);  // before the outage: nothing is taken yet
  monitor.after_update(0.9, full);
  monitor.before_update(1.1, full);
  monitor.after_update(1.1, less);
  monitor.observe(1, 1.1, {keys.back()}, truth, 100);  // camera 1 now sees one of the gone ones: still counted
  monitor.observe(0, 1.5, keys, truth, 100);  // a frame of camera 0 inside its outage (the pipeline takes none)
  monitor.after_update(1.5, less);
  monitor.observe(0, 2.0, keys, truth, 0);   // after: nothing to mark
  monitor.observe(0, 2.1, keys, truth, 50);  // marks again
  monitor.after_update(2.1, map_of({}));     // after the outage: not counted
  std::vector<EvaluationSnapshot> snapshots(4);
  const double times[] = {0.5, 1.0, 2.0, 3.0}, recalls[] = {0.8, 0.0, 0.7, 0.75};
  for (int i = 0; i < 4; ++i) {
    snapshots[i].time_s = times[i];
    snapshots[i].cameras.resize(2);
    snapshots[i].cameras[0].recall = recalls[i];
  }
  const auto results = monitor.results(snapshots);
  ASSERT_EQ(results.size(), 1u);
  const OutageResult& r = results[0];
  EXPECT_EQ(r.camera_index, 0u);
  EXPECT_EQ(r.only_seen_voxels, 30u);
  EXPECT_EQ(r.cleared, 4u);
  EXPECT_DOUBLE_EQ(r.first_cleared_s, 1.1);
  EXPECT_EQ(r.frames_in_window, 1u);
  EXPECT_DOUBLE_EQ(r.first_marking_frame_s, 2.1);
  EXPECT_DOUBLE_EQ(r.recall_before, 0.8);     // the last evaluation before 1.0 s
  EXPECT_DOUBLE_EQ(r.recall_resumed_s, 3.0);  // 0.7 < 0.9 * 0.8 <= 0.75
}

}  // namespace
}  // namespace stvl::evaluation

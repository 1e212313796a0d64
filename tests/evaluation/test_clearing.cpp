#include "evaluation/clearing.hpp"

#include <gtest/gtest.h>

#include "evaluation/evaluator.hpp"

namespace stvl::evaluation {
namespace {

TEST(ClearingLatency, SeenThroughAtT0AndRemovedAtT1HasLatencyT1MinusT0) {
  ClearingLatency c;
  const VoxelKey stale{4, 5, 6};
  c.seen_through(stale, 1.0);
  c.seen_through(stale, 1.2);                                 // the first time counts
  c.after_update(1.5, [](const VoxelKey&) { return true; });  // still in the map
  EXPECT_TRUE(c.tracked(stale));
  c.after_update(2.25, [](const VoxelKey&) { return false; });
  EXPECT_FALSE(c.tracked(stale));
  const ClearingResult r = c.result(10.0);
  EXPECT_EQ(r.stale_voxels_seen_through, 1u);
  EXPECT_EQ(r.not_cleared, 0u);
  EXPECT_DOUBLE_EQ(r.max_latency_s, 1.25);
  EXPECT_DOUBLE_EQ(r.mean_latency_s, 1.25);
}

TEST(ClearingLatency, NeverSeenThroughCountsNeitherAsClearedNorAsMissed) {
  ClearingLatency c;
  // The map dropped a stale voxel the camera never showed: nothing to credit or blame.
  c.after_update(3.0, [](const VoxelKey&) { return false; });
  const ClearingResult r = c.result(10.0);
  EXPECT_EQ(r.stale_voxels_seen_through, 0u);
  EXPECT_EQ(r.not_cleared, 0u);
  EXPECT_EQ(r.max_latency_s, 0.0);
}

TEST(ClearingLatency, NotClearedRunsUntilTheEnd) {
  ClearingLatency c;
  c.seen_through({0, 0, 0}, 2.0);
  c.seen_through({1, 0, 0}, 3.0);
  c.after_update(3.5, [](const VoxelKey& k) { return k.x == 0; });  // (1, 0, 0) cleared after 0.5 s
  const ClearingResult r = c.result(12.0);
  EXPECT_EQ(r.stale_voxels_seen_through, 2u);
  EXPECT_EQ(r.not_cleared, 1u);
  EXPECT_DOUBLE_EQ(r.max_latency_s, 10.0);  // (0, 0, 0): 2 s to the end at 12 s
  EXPECT_DOUBLE_EQ(r.mean_latency_s, 5.25);
}

TEST(EvaluationMean, PhantomsAreAveragedAndTheirMaximumKeptApart) {
  std::vector<EvaluationSnapshot> snapshots(4);
  const int phantoms[] = {7, 1, 0, 3};  // the first lies inside the warm-up and is left out
  for (int i = 0; i < 4; ++i) {
    snapshots[i].time_s = 1.0 + i;
    snapshots[i].phantom_obstacles = phantoms[i];
    snapshots[i].f1 = 0.1 * (i + 1);
    snapshots[i].mapped_voxels = 10 + i;
    snapshots[i].observed_truth_voxels = 5;
  }
  const EvaluationMean m = mean_of(snapshots, 0.5);
  EXPECT_EQ(m.snapshots, 3u);
  EXPECT_DOUBLE_EQ(m.phantom_obstacles, 4.0 / 3.0);
  EXPECT_EQ(m.max_phantom_obstacles, 3);
  EXPECT_NEAR(m.f1, 0.3, 1e-12);
  EXPECT_EQ(m.mapped_voxels, 12u);  // (11 + 12 + 13) / 3
  EXPECT_DOUBLE_EQ(m.time_s, 4.0);
  // One snapshot only: it is the mean, even inside the warm-up.
  EXPECT_EQ(mean_of({snapshots[0]}, 10.0).max_phantom_obstacles, 7);
}

// Open floor: an evaluation whose recall window holds no observed truth voxel has no recall, F1 or IoU to give;
// it is left out of their means (not counted as 0), and precision leaves out those without a mapped voxel.
TEST(EvaluationMean, EvaluationsWithNothingToScoreAreLeftOut) {
  std::vector<EvaluationSnapshot> snapshots(4);
  for (int i = 0; i < 4; ++i) snapshots[i].time_s = 1.0 + i;
  snapshots[0].observed_truth_voxels = 8, snapshots[0].mapped_voxels = 8;
  snapshots[0].recall = 0.8, snapshots[0].f1 = 0.9, snapshots[0].iou = 0.7, snapshots[0].precision = 1.0;
  snapshots[1].mapped_voxels = 8, snapshots[1].precision = 0.5;  // nothing seen, old voxels still mapped
  snapshots[2].observed_truth_voxels = 4, snapshots[2].mapped_voxels = 4;
  snapshots[2].recall = 0.6, snapshots[2].f1 = 0.7, snapshots[2].iou = 0.5, snapshots[2].precision = 0.8;
  // snapshots[3]: nothing seen, nothing mapped
  const EvaluationMean m = mean_of(snapshots, 0.0);
  EXPECT_EQ(m.snapshots, 4u);
  EXPECT_EQ(m.empty_snapshots, 2u);
  EXPECT_DOUBLE_EQ(m.recall, 0.7);  // (0.8 + 0.6) / 2, not / 4
  EXPECT_DOUBLE_EQ(m.f1, 0.8);
  EXPECT_DOUBLE_EQ(m.iou, 0.6);
  EXPECT_NEAR(m.precision, (1.0 + 0.5 + 0.8) / 3, 1e-12);
}

}  // namespace
}  // namespace stvl::evaluation

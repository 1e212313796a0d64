// The figures of metrics.hpp on hand-made sets, with the expected values worked out here.
#include "evaluation/metrics.hpp"

#include <gtest/gtest.h>

namespace stvl::evaluation {
namespace {

CellGrid cells(const std::vector<CellKey>& keys) { return CellGrid::of(keys); }

TEST(VoxelScores, OneFalseVoxelAmongNGivesPrecisionNMinusOneOverN) {
  for (std::size_t n : {1u, 2u, 7u, 1000u}) {
    VoxelMatches m;
    m.mapped = n, m.matched_mapped = n - 1;
    m.observed_truth = 10, m.matched_truth = 10;
    const VoxelScores s = voxel_scores(m);
    EXPECT_DOUBLE_EQ(s.precision, double(n - 1) / n) << n;
    EXPECT_DOUBLE_EQ(s.recall, 1.0);
    // IoU = matched truth / (observed truth + unmatched mapped) = 10 / 11.
    EXPECT_DOUBLE_EQ(s.iou, 10.0 / 11.0);
    if (n > 1) {
      EXPECT_DOUBLE_EQ(s.f1, 2 * s.precision / (s.precision + 1.0));
    }
  }
}

TEST(VoxelScores, EmptyDenominatorsGiveZeroNotNan) {
  const VoxelScores s = voxel_scores({});
  EXPECT_EQ(s.precision, 0.0);
  EXPECT_EQ(s.recall, 0.0);
  EXPECT_EQ(s.f1, 0.0);
  EXPECT_EQ(s.iou, 0.0);
}

TEST(NearVoxel, ChebyshevDistanceInVoxels) {
  const VoxelSet set{{0, 0, 0}};
  EXPECT_TRUE(near_voxel(set, {0, 0, 0}, 0));
  EXPECT_FALSE(near_voxel(set, {1, 0, 0}, 0));
  EXPECT_TRUE(near_voxel(set, {1, -1, 1}, 1));  // a corner neighbour is one voxel away
  EXPECT_FALSE(near_voxel(set, {2, 0, 0}, 1));
  EXPECT_TRUE(near_voxel(set, {-2, 2, 2}, 2));
  const CellGrid grid = cells({{5, 5}});
  EXPECT_TRUE(grid.near({6, 4}, 1));
  EXPECT_FALSE(grid.near({7, 5}, 1));
}

TEST(Obstacles, HalfOfTheObservedVoxelsMappedIsDetectedFewerIsNot) {
  ObstacleResult half{"half"}, fewer{"fewer"}, unseen{"unseen"};
  update_obstacle(half, 10, 5, 3);
  update_obstacle(fewer, 10, 4, 3);
  update_obstacle(unseen, 2, 2, 3);  // 2 of 3 needed to count as observed
  EXPECT_TRUE(half.observed && half.detected);
  EXPECT_DOUBLE_EQ(half.best_recall, 0.5);
  EXPECT_TRUE(fewer.observed);
  EXPECT_FALSE(fewer.detected);
  EXPECT_DOUBLE_EQ(fewer.best_recall, 0.4);
  EXPECT_FALSE(unseen.observed || unseen.detected);
  EXPECT_EQ(unseen.observed_voxels, 2u);
  // Detection sticks once reached; the best recall is the best at one evaluation.
  update_obstacle(half, 12, 1, 3);
  EXPECT_TRUE(half.detected);
  EXPECT_DOUBLE_EQ(half.best_recall, 0.5);
  EXPECT_EQ(half.observed_voxels, 12u);
}

TEST(Costmap, PrecisionAndRecallAgainstFootprintsWithinTolerance) {
  const CellGrid footprint = cells({{0, 0}, {1, 0}, {2, 0}});
  const CellGrid observed = cells({{0, 0}, {1, 0}, {2, 0}});
  // With tol 1: (3, 0) is one cell from the footprint (true), (5, 5) is false; every observed cell has a
  // lethal cell within one cell, so nothing is missed.
  const CellGrid lethal = cells({{0, 0}, {3, 0}, {5, 5}});
  const CostmapMatches tol1 = match_costmap(lethal, footprint, observed, 1);
  EXPECT_DOUBLE_EQ(tol1.precision, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(tol1.recall, 1.0);
  EXPECT_EQ(tol1.false_positive, std::vector<CellKey>({{5, 5}}));
  const CostmapMatches tol0 = match_costmap(lethal, footprint, observed, 0);
  EXPECT_DOUBLE_EQ(tol0.precision, 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(tol0.recall, 1.0 / 3.0);  // (1, 0) and (2, 0) missed
  EXPECT_EQ(tol0.false_negative.size(), 2u);
}

TEST(Costmap, LethalCellsAreKeyedAtTheirCentres) {
  mapping::Costmap2D costmap;
  costmap.width = 3, costmap.height = 2, costmap.resolution_m = 0.05, costmap.origin_m = {-0.05, 1.0};
  costmap.cells.assign(6, mapping::kCostFree);
  costmap.cells[1] = mapping::kCostLethal;  // ix 1, iy 0: centre (0.025, 1.025)
  costmap.cells[5] = mapping::kCostLethal;  // ix 2, iy 1: centre (0.075, 1.075)
  costmap.cells[3] = mapping::kCostUnknown;
  EXPECT_EQ(lethal_cells(costmap, 0.05).cells(), (std::vector<CellKey>{{0, 20}, {1, 21}}));
}

TEST(Phantoms, ALethalGroupBeyondTheClearanceIsAPhantomAndOneWithinIsNot) {
  // 1 cm cells: the clearance of 0.10 m is 10 cells between cell centres.
  const double cell_m = 0.01, clearance_m = 0.10;
  const CellGrid footprint = cells({{0, 0}});
  const CellGrid at_11cm = cells({{11, 0}, {12, 0}});  // 0.11 m from the footprint: a phantom
  const CellGrid at_9cm = cells({{0, 9}, {1, 10}});    // 0.09 m (Chebyshev) from it: an obstacle's edge
  const auto far = find_phantoms(at_11cm, footprint, cell_m, clearance_m, 2);
  ASSERT_EQ(far.size(), 1u);
  EXPECT_EQ(far[0].cells, 2u);
  EXPECT_NEAR(far[0].x_m, 0.12, 1e-12);  // mean of the centres 0.115 and 0.125
  EXPECT_NEAR(far[0].y_m, 0.005, 1e-12);
  EXPECT_TRUE(find_phantoms(at_9cm, footprint, cell_m, clearance_m, 2).empty());
}

// nav2's master costmap against the truth: its window's origin is not on the truth's grid and its resolution may
// differ; each lethal cell stands for the truth cells whose centres it holds.
TEST(Phantoms, AnotherCostmapsLethalCellsAgainstTheTruth) {
  const CellGrid footprint = cells({{0, 0}, {1, 0}});  // true cells of 0.05 m: x 0..0.1, y 0..0.05
  mapping::Costmap2D master;
  master.width = 20, master.height = 20, master.resolution_m = 0.05, master.origin_m = {-0.01, -0.01};
  master.cells.assign(400, mapping::kCostFree);
  const auto lethal = [&](int ix, int iy) {
    master.cells[static_cast<std::size_t>(iy * 20 + ix)] = mapping::kCostLethal;
  };
  lethal(0, 0);    // [-0.01, 0.04)^2 holds the centre (0.025, 0.025): true cell (0, 0)
  lethal(12, 12);  // [0.59, 0.64)^2 holds (0.625, 0.625): cell (12, 12), far from the truth
  lethal(13, 12);  // its neighbour: with it a phantom of 2 cells
  lethal(3, 0);    // holds cell (3, 0): within tolerance 1 of (1, 0)? no (2 cells away); with tolerance 2 yes
  LethalVsTruth r = lethal_against_truth(master, footprint, 0.05, 1, 0.10, 2);
  EXPECT_EQ(r.lethal, 4u);
  EXPECT_EQ(r.false_lethal, 3u);
  ASSERT_EQ(r.phantoms.size(), 1u);
  EXPECT_EQ(r.phantoms[0].cells, 2u);
  EXPECT_NEAR(r.phantoms[0].x_m, 0.65, 1e-12);  // centres 0.625 and 0.675
  EXPECT_EQ(lethal_against_truth(master, footprint, 0.05, 2, 0.10, 2).false_lethal, 2u);
  // A coarser master (0.1 m) from -0.01: its cell (0, 0) holds the truth cells (0, 0), (1, 0), (0, 1), (1, 1).
  master.resolution_m = 0.1;
  master.cells.assign(400, mapping::kCostFree);
  lethal(0, 0);
  lethal(5, 5);  // [0.49, 0.59)^2: cells 10, 11 each way, one cell of 4 truth cells: a phantom
  r = lethal_against_truth(master, footprint, 0.05, 0, 0.10, 2);
  EXPECT_EQ(r.lethal, 2u);
  EXPECT_EQ(r.false_lethal, 1u);
  ASSERT_EQ(r.phantoms.size(), 1u);
  EXPECT_EQ(r.phantoms[0].cells, 4u);
  EXPECT_NEAR(r.phantoms[0].x_m, 0.55, 1e-12);
  // Nothing lethal: nothing false.
  master.cells.assign(400, mapping::kCostFree);
  r = lethal_against_truth(master, footprint, 0.05, 1, 0.10, 2);
  EXPECT_EQ(r.lethal + r.false_lethal + r.phantoms.size(), 0u);
}

TEST(Phantoms, GroupsAreEightConnectedSortedAndAtLeastMinCells) {
  const CellGrid footprint = cells({{-100, -100}});
  // One diagonal group of 3 cells, one single cell, one pair; min_cells 2 drops the single one.
  const CellGrid lethal = cells({{10, 10}, {11, 11}, {12, 12}, {30, 0}, {20, 5}, {20, 6}});
  const auto phantoms = find_phantoms(lethal, footprint, 0.05, 0.10, 2);
  ASSERT_EQ(phantoms.size(), 2u);
  EXPECT_EQ(phantoms[0].cells, 3u);  // x 0.575 < 1.025
  EXPECT_EQ(phantoms[1].cells, 2u);
  EXPECT_LT(phantoms[0].x_m, phantoms[1].x_m);
  EXPECT_EQ(find_phantoms(lethal, footprint, 0.05, 0.10, 1).size(), 3u);
}

// The projection guard counts both kinds of mismatch between lethal cells and the voxel columns, in the band and
// at the mark threshold; the map's own projection passes it.
TEST(ProjectionGuard, CountsGhostsAndColumnsWithoutLethal) {
  mapping::StvlConfig config;
  config.voxel_size_m = 0.1;
  config.mark_threshold = 2;
  mapping::VoxelMap map(config);
  // Column (1, 1): 2 voxels in the band (lethal at threshold 2); (2, 1): 1 voxel (not lethal); (3, 1): 2 voxels
  // but one above the band (z = 2.05 m).
  map.set_voxels({{{1, 1, 2}, 1.0}, {{1, 1, 3}, 1.0}, {{2, 1, 2}, 1.0}, {{3, 1, 2}, 1.0}, {{3, 1, 20}, 1.0}});
  mapping::CostmapOptions options;
  options.min_obstacle_height_m = 0.1;
  options.max_obstacle_height_m = 2.0;
  const CellGrid projected = lethal_cells(map.project_costmap(options), 0.1);
  EXPECT_EQ(projected.cells(), (std::vector<CellKey>{{1, 1}}));
  ProjectionGuard g = guard_projection(map, projected, 0.1, 2.0);
  EXPECT_EQ(g.lethal_without_voxels, 0u);
  EXPECT_EQ(g.columns_without_lethal, 0u);
  g = guard_projection(map, cells({{1, 1}, {2, 1}, {3, 1}, {9, 9}}), 0.1, 2.0);  // three ghosts
  EXPECT_EQ(g.lethal_without_voxels, 3u);
  EXPECT_EQ(g.columns_without_lethal, 0u);
  g = guard_projection(map, {}, 0.1, 2.0);  // the lethal column lost
  EXPECT_EQ(g.lethal_without_voxels, 0u);
  EXPECT_EQ(g.columns_without_lethal, 1u);
  g = guard_projection(map, {}, 0.1, 3.0);  // a wider band makes (3, 1) count too
  EXPECT_EQ(g.columns_without_lethal, 2u);
}

// Footprint clearing frees columns on purpose: the guard does not count them as lost.
TEST(ProjectionGuard, ColumnsFreedByTheFootprintAreNotLost) {
  mapping::StvlConfig config;
  config.voxel_size_m = 0.1;
  mapping::VoxelMap map(config);
  map.set_voxels({{{1, 1, 5}, 1.0}, {{4, 1, 5}, 1.0}});
  EXPECT_EQ(guard_projection(map, {}, 0.0, 2.0).columns_without_lethal, 2u);
  EXPECT_EQ(guard_projection(map, {}, 0.0, 2.0, {{1, 1}}).columns_without_lethal, 1u);
}

// A square footprint 0.05..0.35 m at 0.1 m cells: its convex fill is cells 0..3 x 0..3; the ring takes cells
// whose centres lie within 0.10 m outside it.
TEST(SelfMarking, CountsLethalCellsInsideTheFootprintAndInItsRing) {
  const std::vector<Eigen::Vector2d> square{{0.05, 0.05}, {0.35, 0.05}, {0.35, 0.35}, {0.05, 0.35}};
  const CellGrid lethal = cells({{1, 1},
                                 {2, 3},  // inside
                                 {4, 1},
                                 {-1, 1},  // centres 0.10 m outside the edges x = 0.35 and x = 0.05
                                 {5, 1},   // 0.20 m outside
                                 {4, 4},   // 0.14 m from the corner
                                 {20, 20}});
  SelfMarking s = count_self_marking(lethal, square, 0.1, 0.10, {}, 1);
  EXPECT_EQ(s.inside, 2u);
  EXPECT_EQ(s.ring, 2u);
  EXPECT_EQ(s.total(), 4u);
  // A true obstacle beside the robot at (5, 2): (4, 1) within one cell of it is the obstacle, not the robot.
  s = count_self_marking(lethal, square, 0.1, 0.10, cells({{5, 2}}), 1);
  EXPECT_EQ(s.inside, 2u);
  EXPECT_EQ(s.ring, 1u);
  s = count_self_marking(lethal, square, 0.1, 0.25, {}, 0);  // a wider ring reaches (5, 1) and (4, 4)
  EXPECT_EQ(s.ring, 4u);
  EXPECT_EQ(count_self_marking({}, square, 0.1, 0.10, {}, 1).total(), 0u);
  EXPECT_EQ(count_self_marking(lethal, {{0, 0}, {1, 1}}, 0.1, 0.10, {}, 1).total(), 0u);  // no footprint
}

// Issue 31: lethal cells where the truth is free within the corridor around the path, the first along it named.
TEST(PathBlock, CountsFreeLethalCellsWithinTheCorridorOfThePath) {
  const std::vector<Eigen::Vector2d> path{{0.0, 0.0}, {2.0, 0.0}, {2.0, 2.0}};
  // Centres at 0.1 m cells: (1.05, 0.05) on the first leg, (2.25, 1.05) 0.25 m beside the second,
  // (1.05, 0.55) 0.55 m off, (-0.55, 0.05) 0.55 m before the start.
  const std::vector<CellKey> cells{{22, 10}, {10, 0}, {10, 5}, {-6, 0}};
  const PathBlock b = lethal_near_path(cells, path, 0.1, 0.35);
  EXPECT_EQ(b.cells, 2u);
  EXPECT_NEAR(b.first_x_m, 1.05, 1e-9);
  EXPECT_NEAR(b.first_y_m, 0.05, 1e-9);
  EXPECT_NEAR(b.first_along_m, 1.05, 1e-9);
  EXPECT_EQ(lethal_near_path(cells, path, 0.1, 0.6).cells, 4u);
  EXPECT_EQ(lethal_near_path(cells, {{0.0, 0.0}}, 0.1, 0.35).cells, 0u);  // no path, nothing blocks it
  EXPECT_EQ(lethal_near_path({}, path, 0.1, 0.35).cells, 0u);
}

TEST(DistanceStats, NearestRankQuantiles) {
  std::vector<double> d;
  for (int i = 100; i >= 0; --i) d.push_back(i * 0.001);  // 0 .. 0.1 m, unsorted
  const DistanceStats s = distance_stats(d);
  EXPECT_EQ(s.count, 101u);
  EXPECT_NEAR(s.mean_m, 0.05, 1e-12);
  EXPECT_DOUBLE_EQ(s.median_m, 0.050);
  EXPECT_DOUBLE_EQ(s.p90_m, 0.090);
  EXPECT_DOUBLE_EQ(s.p99_m, 0.099);
  EXPECT_DOUBLE_EQ(s.max_m, 0.100);
  EXPECT_EQ(distance_stats({}).count, 0u);
}

// The evaluator keeps counts per distinct distance (a soak's vector grew without end): the same figures, bit for bit.
TEST(DistanceStats, CountsGiveTheSameFiguresAsTheValues) {
  std::vector<double> d;
  std::map<double, std::size_t> counts;
  for (int i = 0; i < 5000; ++i) {
    const double v = 0.001 * ((i * 7919) % 613) + 1e-7 * (i % 3);  // repeats and near-repeats, unsorted
    d.push_back(v);
    ++counts[v];
  }
  const DistanceStats a = distance_stats(d), b = distance_stats_of_counts(counts);
  EXPECT_EQ(a.count, b.count);
  EXPECT_EQ(a.mean_m, b.mean_m);
  EXPECT_EQ(a.median_m, b.median_m);
  EXPECT_EQ(a.p90_m, b.p90_m);
  EXPECT_EQ(a.p99_m, b.p99_m);
  EXPECT_EQ(a.max_m, b.max_m);
  EXPECT_LT(counts.size(), d.size() / 2);
  EXPECT_EQ(distance_stats_of_counts({}).count, 0u);
  const DistanceStats one = distance_stats_of_counts({{0.25, 3}});
  EXPECT_EQ(one.median_m, 0.25);
  EXPECT_EQ(one.max_m, 0.25);
}

}  // namespace
}  // namespace stvl::evaluation

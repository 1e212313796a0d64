// CellGrid and SeenVoxels, the dense cell sets and the sorted seen-voxel list of the evaluation, against plain
// references written here with hash sets and maps (the containers they replaced), on random inputs.
#include "evaluation/cell_grid.hpp"
#include "evaluation/metrics.hpp"
#include "evaluation/seen_voxels.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <stdexcept>

namespace stvl::evaluation {
namespace {

bool near_in(const CellSet& set, const CellKey& c, int tol) {
  for (int dx = -tol; dx <= tol; ++dx)
    for (int dy = -tol; dy <= tol; ++dy)
      if (set.count({c.x + dx, c.y + dy})) return true;
  return false;
}

CellSet random_cells(std::mt19937& rng, int n, int lo, int hi) {
  std::uniform_int_distribution<int> coord(lo, hi);
  CellSet out;
  for (int i = 0; i < n; ++i) out.insert({coord(rng), coord(rng)});
  return out;
}

TEST(CellGrid, MembershipCountsAndTheBox) {
  CellGrid grid({-3, 2}, {4, 5});
  EXPECT_TRUE(grid.empty());
  EXPECT_TRUE(grid.covers({-3, 2}) && grid.covers({4, 5}));
  EXPECT_FALSE(grid.covers({5, 5}) || grid.covers({-3, 1}));
  grid.insert({-3, 2});
  grid.insert({-3, 2});  // once
  grid.add({4, 5}, 3);
  EXPECT_EQ(grid.size(), 2u);
  EXPECT_EQ(grid.count({4, 5}), 3);
  EXPECT_FALSE(grid.contains({100, 100}));  // outside the box: absent, not an error
  grid.add({4, 5}, -3);
  EXPECT_EQ(grid.size(), 1u);
  grid.add({4, 5}, -1);  // never below 0
  EXPECT_EQ(grid.count({4, 5}), 0);
  grid.add({4, 5}, 1);
  EXPECT_EQ(grid.count({4, 5}), 1);
  grid.add({0, 3}, 70000);  // at most 65535
  EXPECT_EQ(grid.count({0, 3}), 65535);
  EXPECT_EQ(grid.size(), 3u);
  EXPECT_THROW(grid.insert({5, 5}), std::out_of_range);
  EXPECT_THROW(CellGrid({-2000000000, -2000000000}, {2000000000, 2000000000}), std::invalid_argument);
  // A large box costs only the tiles in use: two cells 100000 cells (2 km at 0.02 m) apart.
  CellGrid sparse({-50000, -50000}, {50000, 50000});
  sparse.insert({-50000, 5});
  sparse.insert({50000, -70});
  EXPECT_EQ(sparse.size(), 2u);
  EXPECT_TRUE(sparse.contains({50000, -70}) && sparse.near({49999, -69}, 1) && !sparse.near({0, 0}, 100));
  EXPECT_EQ(sparse.cells(), (std::vector<CellKey>{{50000, -70}, {-50000, 5}}));  // rows of tiles in y order
  EXPECT_EQ(CellGrid().size(), 0u);
  EXPECT_FALSE(CellGrid().near({0, 0}, 5));
  // Within a tile row by row: y first, then x.
  const CellGrid rows = CellGrid::of(std::vector<CellKey>{{2, 1}, {0, 1}, {5, 0}});
  EXPECT_EQ(rows.cells(), (std::vector<CellKey>{{5, 0}, {0, 1}, {2, 1}}));
}

TEST(CellGrid, NearMatchesTheHashSetNeighbourTestAtTheBoxEdges) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    const CellSet set = random_cells(rng, 60, -70, 70);  // several 64 x 64 tiles, empty ones among them
    const CellGrid grid = CellGrid::of(set);
    EXPECT_EQ(grid.to_set(), set);
    for (int tol : {0, 1, 3})
      for (int x = -76; x <= 76; ++x)
        for (int y = -76; y <= 76; ++y) ASSERT_EQ(grid.near({x, y}, tol), near_in(set, {x, y}, tol)) << x << " " << y;
  }
}

// The costmap figures against the hash-set definitions they were computed with before.
TEST(CellGrid, CostmapMatchesPhantomsAndGuardEqualThePlainHashSetLoops) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 30; ++trial) {
    const CellSet lethal = random_cells(rng, 300, 0, 100), footprint = random_cells(rng, 400, -5, 105),
                  observed = random_cells(rng, 200, -5, 105);
    const int tol = trial % 3;
    const CostmapMatches m = match_costmap(CellGrid::of(lethal), CellGrid::of(footprint), CellGrid::of(observed), tol);
    std::size_t lethal_true = 0, observed_hit = 0;
    for (const CellKey& c : lethal) lethal_true += near_in(footprint, c, tol);
    for (const CellKey& c : observed) observed_hit += near_in(lethal, c, tol);
    EXPECT_EQ(m.lethal, lethal.size());
    EXPECT_EQ(m.lethal_true, lethal_true);
    EXPECT_EQ(m.observed_hit, observed_hit);
    EXPECT_EQ(m.true_positive.size() + m.false_positive.size(), lethal.size());
    EXPECT_EQ(m.false_negative.size(), observed.size() - observed_hit);

    // Phantoms: flood fill over 8-neighbours, then the clearance test per group.
    const int clearance_cells = 3;
    std::vector<Phantom> expected;
    CellSet visited;
    for (const CellKey& start : lethal) {
      if (!visited.insert(start).second) continue;
      std::vector<CellKey> stack{start}, group;
      while (!stack.empty()) {
        const CellKey c = stack.back();
        stack.pop_back();
        group.push_back(c);
        for (int dx = -1; dx <= 1; ++dx)
          for (int dy = -1; dy <= 1; ++dy)
            if (lethal.count({c.x + dx, c.y + dy}) && visited.insert({c.x + dx, c.y + dy}).second)
              stack.push_back({c.x + dx, c.y + dy});
      }
      const bool near = std::any_of(group.begin(), group.end(),
                                    [&](const CellKey& c) { return near_in(footprint, c, clearance_cells); });
      if (near || group.size() < 2) continue;
      double x = 0, y = 0;
      for (const CellKey& c : group) x += (c.x + 0.5) * 0.1, y += (c.y + 0.5) * 0.1;
      expected.push_back({x / group.size(), y / group.size(), group.size()});
    }
    std::sort(expected.begin(), expected.end(),
              [](const Phantom& a, const Phantom& b) { return a.x_m < b.x_m || (a.x_m == b.x_m && a.y_m < b.y_m); });
    const std::vector<Phantom> phantoms = find_phantoms(CellGrid::of(lethal), CellGrid::of(footprint), 0.1, 0.3, 2);
    ASSERT_EQ(phantoms.size(), expected.size());
    for (std::size_t i = 0; i < phantoms.size(); ++i) {
      EXPECT_EQ(phantoms[i].cells, expected[i].cells);
      EXPECT_NEAR(phantoms[i].x_m, expected[i].x_m, 1e-12);
      EXPECT_NEAR(phantoms[i].y_m, expected[i].y_m, 1e-12);
    }

    // The projection guard from per-column counts.
    std::map<CellKey, int> counts;
    std::uniform_int_distribution<int> count(1, 3);
    for (const CellKey& c : random_cells(rng, 100, 0, 40)) counts[c] = count(rng);
    std::vector<CellKey> columns;
    for (const auto& [c, n] : counts) columns.push_back(c);
    CellGrid count_grid = CellGrid::covering(columns);
    for (const auto& [c, n] : counts) count_grid.add(c, n);
    const CellSet freed = random_cells(rng, 20, 0, 40);
    std::size_t without_voxels = 0, without_lethal = 0;
    for (const CellKey& c : lethal) without_voxels += !counts.count(c) || counts[c] < 2;
    for (const auto& [c, n] : counts) without_lethal += n >= 2 && !lethal.count(c) && !freed.count(c);
    const ProjectionGuard g = guard_projection(count_grid, 2, CellGrid::of(lethal), freed);
    EXPECT_EQ(g.lethal_without_voxels, without_voxels);
    EXPECT_EQ(g.columns_without_lethal, without_lethal);
  }
}

// SeenVoxels::record() and forget_before() against a map of key -> last time, over random frames; what an entry
// remembers (static_body, off_truth) survives while the voxel stays within the window.
TEST(SeenVoxels, RecordAndForgetMatchAMapOfLastTimes) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> coord(-6, 6);
  SeenVoxels seen;
  std::map<VoxelKey, double> reference;
  const double window_s = 0.5;
  for (int frame = 0; frame < 200; ++frame) {
    const double time_s = frame * 0.1;
    std::vector<VoxelKey> keys;
    for (int i = 0; i < 40; ++i) keys.push_back({coord(rng), coord(rng), coord(rng) / 3});
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    std::size_t called = 0;
    seen.record(keys, time_s, time_s - window_s, [&](SeenVoxels::Entry& e) {
      ++called;
      if (e.static_body == SeenVoxels::Entry::kUnknown) e.static_body = e.key.x;  // remembered from then on
      EXPECT_EQ(e.static_body, e.key.x);
      EXPECT_EQ(e.time_s, time_s);
    });
    EXPECT_EQ(called, keys.size());
    for (const VoxelKey& k : keys) reference[k] = time_s;
    if (frame % 7 == 0) {
      seen.forget_before(time_s - window_s / 2);
      for (auto it = reference.begin(); it != reference.end();)
        it = it->second < time_s - window_s / 2 ? reference.erase(it) : std::next(it);
    }
    for (auto it = reference.begin(); it != reference.end();)
      it = it->second < time_s - window_s ? reference.erase(it) : std::next(it);
    ASSERT_EQ(seen.size(), reference.size()) << frame;
    auto it = reference.begin();
    for (const SeenVoxels::Entry& e : seen.entries()) {
      ASSERT_EQ(e.key, it->first);
      ASSERT_EQ(e.time_s, it->second);
      ++it;
    }
  }
}

}  // namespace
}  // namespace stvl::evaluation

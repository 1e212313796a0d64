// MappedIndex (evaluation/mapped_index.hpp) against its definition, reference::match_mapped()
// (evaluation/reference/), on the fixture's box-and-cart world: a static box and a mocap cart that moves between
// evaluations (next to the box, away from it, back), with random maps that change between calls (voxels added and
// removed, whole leaves emptied), with and without update() between evaluations; and metrics.hpp's
// column_counts(), a leaf at a time, against a count per voxel.
#include "evaluation/mapped_index.hpp"
#include "evaluation/reference/mapped_index.hpp"
#include "tests/evaluation/box_face.hpp"
#include "tests/support/fixture.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include <random>
#include <vector>

namespace stvl::evaluation {
namespace {

// A grid's cells with their counts, sorted by cell (x, then y).
std::vector<std::pair<CellKey, int>> counts_of(const CellGrid& grid) {
  std::vector<std::pair<CellKey, int>> out;
  grid.for_each([&](const CellKey& c, int n) { out.emplace_back(c, n); });
  std::sort(out.begin(), out.end());
  return out;
}

constexpr const char* kWorld = stvl::test::kBoxAndCartWorld;  // the box, and the cart the test moves
EvaluationConfig config(int tol) { return test::config_at_0p1(tol); }

void move_cart(sim::World& world, double x, double y) {
  world.data()->mocap_pos[0] = x, world.data()->mocap_pos[1] = y;
  world.forward();
}

// Random voxels around both bodies, dense next to the box's face and the cart's path.
std::vector<VoxelKey> random_keys(std::mt19937& rng, std::size_t n) {
  std::uniform_int_distribution<int> x(-30, 40), y(-15, 15), z(0, 9);
  std::vector<VoxelKey> keys;
  for (std::size_t i = 0; i < n; ++i) keys.push_back({x(rng), y(rng), z(rng)});
  return keys;
}

class MappedIndexTest : public ::testing::TestWithParam<int> {};

TEST_P(MappedIndexTest, EqualsThePlainDefinitionAsTheMapAndTheCartChange) {
  const int tol = GetParam();
  sim::World world = sim::World::from_string(kWorld);
  Truth plain_truth(world, config(tol)), index_truth(world, config(tol));
  mapping::StvlConfig map_config;
  map_config.voxel_size_m = 0.1;
  mapping::VoxelMap map(map_config);
  MappedIndex index;
  std::map<double, std::size_t> plain_counts;
  std::mt19937 rng(7);
  const std::vector<std::pair<double, double>> cart_xy = {{1.0, 0.0},  {1.0, 0.0}, {1.8, 0.0},  {-2.0, 1.2},
                                                          {-2.0, 1.2}, {1.9, 0.3}, {3.2, -0.9}, {1.0, 0.0}};
  std::size_t matched_seen = 0, unmatched_seen = 0;
  for (std::size_t step = 0; step < cart_xy.size() * 3; ++step) {
    if (step % 3 == 0) {
      move_cart(world, cart_xy[step / 3].first, cart_xy[step / 3].second);
      plain_truth.update(world), index_truth.update(world);
    }
    std::vector<mapping::Voxel> added;
    for (const auto& k : random_keys(rng, 400)) added.push_back({k, static_cast<double>(step)});
    map.set_voxels(added);
    if (step % 2 == 1) index.update(map, index_truth);       // between evaluations: results computed ahead
    std::vector<VoxelKey> removed = random_keys(rng, 1500);  // some of them mapped
    if (step % 4 == 1) {                                     // a whole region goes: leaves emptied
      for (const auto& k : map.voxel_keys())
        if (k.x < 0) removed.push_back(k);
    }
    map.erase(removed);
    const VoxelMatches plain = reference::match_mapped(map, plain_truth, tol, plain_counts);
    const VoxelMatches indexed = index.match(map, index_truth);
    ASSERT_EQ(indexed.mapped, plain.mapped) << "step " << step;
    ASSERT_EQ(indexed.matched_mapped, plain.matched_mapped) << "step " << step;
    ASSERT_EQ(index.distance_counts(), plain_counts) << "step " << step;
    std::map<CellKey, int> columns;  // the plain count, a voxel at a time
    map.for_each_key([&](const VoxelKey& k) {
      const double z_m = (k.z + 0.5) * 0.1;
      if (z_m >= 0.25 && z_m <= 0.75) ++columns[{k.x, k.y}];
    });
    ASSERT_EQ(counts_of(column_counts(map, 0.25, 0.75)),
              (std::vector<std::pair<CellKey, int>>(columns.begin(), columns.end())))
        << "step " << step;
    for (const auto& k : random_keys(rng, 300)) {
      ASSERT_EQ(index.contains(k), map.contains(k));
      for (int t = 0; t <= 1; ++t)
        ASSERT_EQ(index.near(k, t), any_within(k, t, [&](const VoxelKey& n) { return map.contains(n); }));
    }
    matched_seen += plain.matched_mapped, unmatched_seen += plain.mapped - plain.matched_mapped;
  }
  EXPECT_GT(matched_seen, 100u);  // both outcomes occur: the comparison is not vacuous
  EXPECT_GT(unmatched_seen, 1000u);
}

INSTANTIATE_TEST_SUITE_P(Tolerance, MappedIndexTest, ::testing::Values(0, 1));

TEST(MappedIndex, ForgetsLeavesThatLeftTheMap) {
  sim::World world = sim::World::from_string(kWorld);
  Truth truth(world, config(1));
  mapping::StvlConfig map_config;
  map_config.voxel_size_m = 0.1;
  mapping::VoxelMap map(map_config);
  map.set_voxels({{{20, 0, 3}, 0.0}, {{-40, 0, 3}, 0.0}});
  MappedIndex index;
  EXPECT_EQ(index.match(map, truth).matched_mapped, 1u);
  EXPECT_EQ(index.leaves(), 2u);
  map.erase({{-40, 0, 3}});
  EXPECT_EQ(index.match(map, truth).mapped, 1u);
  EXPECT_EQ(index.leaves(), 1u);
  EXPECT_FALSE(index.contains({-40, 0, 3}));
}

}  // namespace
}  // namespace stvl::evaluation

namespace stvl::evaluation {
namespace {

// VoxelMaskSet against the plain VoxelSet it stands in for (Truth's static voxels), on random keys around 0,
// negative ones included, queried in and out of order.
TEST(VoxelMaskSet, AnswersAsTheVoxelSetItReplaces) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> coord(-20, 20);
  VoxelSet plain;
  VoxelMaskSet masks;
  for (int i = 0; i < 5000; ++i) {
    const VoxelKey k{coord(rng), coord(rng), coord(rng)};
    plain.insert(k), masks.insert(k);
  }
  std::size_t hits = 0;
  for (int x = -22; x <= 22; ++x)
    for (int y = -22; y <= 22; ++y)
      for (int z = -22; z <= 22; ++z) {
        const VoxelKey k{x, y, z};
        ASSERT_EQ(masks.contains(k), plain.count(k) > 0) << x << " " << y << " " << z;
        hits += plain.count(k);
      }
  for (int i = 0; i < 20000; ++i) {
    const VoxelKey k{coord(rng), coord(rng), coord(rng)};
    ASSERT_EQ(masks.contains(k), plain.count(k) > 0);
  }
  EXPECT_GT(hits, 4000u);
  // Erases and inserts mixed, looked up in between (the cached leaf stays right through both).
  std::size_t erased = 0;
  for (int i = 0; i < 20000; ++i) {
    const VoxelKey k{coord(rng), coord(rng), coord(rng)};
    if (i % 3 == 0) {
      erased += plain.erase(k);
      masks.erase(k);
    } else if (i % 3 == 1) {
      plain.insert(k), masks.insert(k);
    }
    ASSERT_EQ(masks.contains(k), plain.count(k) > 0);
  }
  EXPECT_GT(erased, 500u);
  std::size_t visited = 0, in_plain = 0;
  masks.for_each([&](const VoxelKey& k) { ++visited, in_plain += plain.count(k); });
  EXPECT_EQ(visited, plain.size());
  EXPECT_EQ(in_plain, plain.size());
}

// Labels (Truth's body per static voxel) against the map they replace, filled with emplace() in body order: the
// first label of a key stays. Bodies are boxes that overlap, so leaves with one label and with several both occur.
TEST(VoxelMaskSet, LabelsAnswerAsAMapFilledWithEmplace) {
  std::mt19937 rng(4);
  std::uniform_int_distribution<int> corner(-10, 6), extent(0, 9);
  std::unordered_map<VoxelKey, int, VoxelKeyHash> plain;
  VoxelMaskSet masks;
  for (int body = 0; body < 20; ++body) {
    const int x0 = corner(rng), y0 = corner(rng), z0 = corner(rng), dx = extent(rng), dy = extent(rng),
              dz = extent(rng);
    for (int x = x0; x <= x0 + dx; ++x)
      for (int y = y0; y <= y0 + dy; ++y)
        for (int z = z0; z <= z0 + dz; ++z) plain.emplace(VoxelKey{x, y, z}, body), masks.insert({x, y, z}, body);
  }
  std::size_t found = 0;
  for (int x = -12; x <= 17; ++x)
    for (int y = -12; y <= 17; ++y)
      for (int z = -12; z <= 17; ++z) {
        const auto it = plain.find({x, y, z});
        ASSERT_EQ(masks.label_of({x, y, z}), it == plain.end() ? -1 : it->second) << x << " " << y << " " << z;
        found += it != plain.end();
      }
  EXPECT_EQ(found, plain.size());
  std::size_t visited = 0;
  masks.for_each([&](const VoxelKey& k) { visited += plain.count(k); });
  EXPECT_EQ(visited, plain.size());
}

}  // namespace
}  // namespace stvl::evaluation

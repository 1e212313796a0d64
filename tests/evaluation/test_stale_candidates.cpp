// StaleCandidates (evaluation/stale_candidates.hpp) against the plain rebuild, on the fixture's box-and-cart world
// with the cart driven through a series of places (overlapping its old ones, and next to the static box).
#include "evaluation/stale_candidates.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "evaluation/reference/stale_candidates.hpp"
#include "tests/evaluation/box_face.hpp"
#include "tests/support/fixture.hpp"

namespace stvl::evaluation {
namespace {

TEST(StaleCandidates, TheIncrementalSetIsTheRebuiltOneAfterEveryMove) {
  sim::World world = sim::World::from_string(stvl::test::kBoxAndCartWorld);
  EvaluationConfig config = test::config_at_0p1(0);
  config.tolerance_voxels = 1;
  Truth truth(world, config);
  StaleCandidates stale;
  stale.update(truth);
  EXPECT_EQ(stale.keys(), reference::stale_candidates(truth));
  const double xs[] = {1.05, 1.3, 1.55, -2.0, -2.05, 1.2, 1.2, 0.4};  // small steps, a jump away and back, a stay
  std::size_t most = 0;
  for (const double x : xs) {
    world.data()->mocap_pos[0] = x;
    world.data()->mocap_pos[1] = 0.05 * x;
    world.forward();
    truth.update(world);
    if (x == 1.3) truth.update(world);  // two updates between looks: the touched voxels pile up
    stale.update(truth);
    const VoxelSet rebuilt = reference::stale_candidates(truth);
    EXPECT_EQ(stale.keys(), rebuilt) << "cart at x = " << x;
    for (const VoxelKey& k : rebuilt) {
      EXPECT_TRUE(stale.lo().x <= k.x && k.x <= stale.hi().x && stale.lo().y <= k.y && k.y <= stale.hi().y &&
                  stale.lo().z <= k.z && k.z <= stale.hi().z);
    }
    most = std::max(most, rebuilt.size());
  }
  EXPECT_GT(most, 100u) << "the cart's old places leave candidates";
}

TEST(StaleCandidates, SortsByThePlaceInTheVacatedSet) {
  sim::World world = sim::World::from_string(stvl::test::kBoxAndCartWorld);
  Truth truth(world, test::config_at_0p1(0));
  world.data()->mocap_pos[0] = -5.0;
  world.forward();
  truth.update(world);
  std::vector<VoxelKey> in_order(truth.vacated().begin(), truth.vacated().end());
  ASSERT_GT(in_order.size(), 10u);
  std::vector<VoxelKey> some = {in_order[7], in_order[2], in_order.back(), in_order[0]};
  sort_in_vacated_order(truth, some);
  EXPECT_EQ(some, (std::vector<VoxelKey>{in_order[0], in_order[2], in_order[7], in_order.back()}));
}

}  // namespace
}  // namespace stvl::evaluation

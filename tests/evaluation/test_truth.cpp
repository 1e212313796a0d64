// Truth's moving bodies (evaluation/truth.hpp) kept from update to update against a truth made afresh at every
// pose: the same voxels, bodies, labels and neighbourhoods, and the vacated set in the order a plain replay of
// the original loop (27 inserts per body voxel, in body and key order) gives it.
#include "evaluation/truth.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "sim/world.hpp"
#include "tests/evaluation/box_face.hpp"

namespace stvl::evaluation {
namespace {

// A static box; a walker (a capsule) that moves and turns; a cart of two geoms that moves now and then; a post
// that never moves; a finite plane on a mocap body (a floor while it lies at z = 0, an obstacle when lifted).
constexpr const char* kMovingWorld = R"(
<mujoco>
  <worldbody>
    <body name="box" pos="2.35 0 0.4"><geom type="box" size="0.3 0.25 0.25"/></body>
    <body name="walker" mocap="true" pos="0 1 0.9"><geom type="capsule" size="0.2 0.6"/></body>
    <body name="cart" mocap="true" pos="1 0 0.3">
      <geom type="box" size="0.15 0.1 0.1"/><geom type="sphere" pos="0 0 0.2" size="0.08"/>
    </body>
    <body name="post" mocap="true" pos="-1 -1 0.5"><geom type="cylinder" size="0.07 0.5"/></body>
    <body name="board" mocap="true" pos="3 2 0"><geom type="plane" size="0.3 0.2 0.1"/></body>
  </worldbody>
</mujoco>)";

std::vector<std::string> names(const Truth& truth) {
  std::vector<std::string> out;
  for (const auto* body : truth.bodies()) out.push_back(body->body_name);
  return out;
}

void check_moving_bodies(const std::string& world_xml, bool with_board) {
  sim::World world = sim::World::from_string(world_xml);
  EvaluationConfig config = test::config_at_0p1(1);
  Truth truth(world, config);
  VoxelSet plain_vacated;  // the original loop, replayed from the bodies after each update
  std::size_t replayed_version = 0;
  const auto replay = [&] {
    if (truth.version() == replayed_version) return;
    replayed_version = truth.version();
    for (const auto* body : truth.bodies()) {
      if (body->body_name == "box") continue;  // the static body
      for (const VoxelKey& k : body->voxels)
        for (int dx = -1; dx <= 1; ++dx)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dz = -1; dz <= 1; ++dz) plain_vacated.insert({k.x + dx, k.y + dy, k.z + dz});
    }
  };
  replay();
  double* walker = world.data()->mocap_pos + 0;
  double* cart = world.data()->mocap_pos + 3;
  double unused[3] = {0, 0, 0};
  double* board = with_board ? world.data()->mocap_pos + 9 : unused;
  double* walker_quat = world.data()->mocap_quat + 0;
  std::size_t boards_seen = 0;
  for (int step = 1; step <= 24; ++step) {
    walker[0] = 0.073 * step, walker[1] = 1.0 - 0.031 * step;
    const double yaw = 0.2 * step;
    walker_quat[0] = std::cos(0.5 * yaw), walker_quat[3] = std::sin(0.5 * yaw);
    if (step % 5 == 0) cart[0] = 1.0 + 0.12 * step;
    board[2] = step % 7 < 3 ? 0.0 : 0.6;  // a floor, then an obstacle, then a floor again
    world.forward();
    truth.update(world);
    if (step == 10) truth.update(world);  // nothing moved: nothing changes
    replay();
    const Truth fresh(world, config);
    ASSERT_EQ(names(truth), names(fresh)) << "step " << step;
    for (std::size_t b = 0; b < fresh.bodies().size(); ++b)
      ASSERT_EQ(truth.bodies()[b]->voxels, fresh.bodies()[b]->voxels)
          << fresh.bodies()[b]->body_name << " step " << step;
    boards_seen += names(truth).back() == "board";
    std::size_t near = 0;
    for (int x = -15; x <= 40; ++x)
      for (int y = -15; y <= 25; ++y)
        for (int z = 0; z <= 20; ++z) {
          const VoxelKey k{x, y, z};
          ASSERT_EQ(truth.contains(k), fresh.contains(k)) << x << " " << y << " " << z;
          ASSERT_EQ(truth.near_moving(k), fresh.near_moving(k)) << x << " " << y << " " << z;
          ASSERT_EQ(truth.near(k, 2), fresh.near(k, 2)) << x << " " << y << " " << z;
          ASSERT_EQ(truth.body_of(k), fresh.body_of(k)) << x << " " << y << " " << z;
          ASSERT_EQ(truth.is_vacated(k), plain_vacated.count(k) > 0) << x << " " << y << " " << z;
          near += truth.near_moving(k);
        }
    EXPECT_GT(near, 500u);
    EXPECT_TRUE(truth.voxel_centers().isApprox(fresh.voxel_centers(), 0.0));
    ASSERT_EQ(std::vector<VoxelKey>(truth.vacated().begin(), truth.vacated().end()),
              std::vector<VoxelKey>(plain_vacated.begin(), plain_vacated.end()))
        << "step " << step;
  }
  if (with_board) {
    EXPECT_GT(boards_seen, 5u);
    EXPECT_LT(boards_seen, 24u);
  } else {
    EXPECT_EQ(boards_seen, 0u);
  }
}

// Without the board the geoms are fixed and update() refreshes their poses only; with it the list is made again.
TEST(Truth, MovingBodiesAsATruthMadeAfreshAndVacatedInThePlainOrder) {
  std::string without_board = kMovingWorld;
  const std::string board_line = without_board.substr(without_board.find("    <body name=\"board\""));
  without_board.erase(without_board.find("    <body name=\"board\""), board_line.find('\n') + 1);
  ASSERT_EQ(without_board.find("board"), std::string::npos);
  {
    SCOPED_TRACE("geoms fixed");
    check_moving_bodies(without_board, false);
  }
  {
    SCOPED_TRACE("a plane on a moving body");
    check_moving_bodies(kMovingWorld, true);
  }
}

}  // namespace
}  // namespace stvl::evaluation

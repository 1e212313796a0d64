// World's static-pair exclusions (sim/world.cpp): bodies welded to the world are excluded from colliding with each
// other, and the physics is bit for bit that of the world compiled as written (MuJoCo's own mj_loadXML).
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <string>
#include <utility>

#include "sim/world.hpp"
#include "tests/support/fixture.hpp"

namespace stvl::sim {
namespace {

// The robot between two walls, a third wall across its path and a walker (mocap) beside it; it drives into the
// wall ahead and turns, touching it, the floor and (by its caster) the ground all along.
constexpr const char* kWalledRobotWorld = R"(
<mujoco>
  <compiler autolimits="true"/>
  <option timestep="0.002"/>
  <include file="robot.xml"/>
  <worldbody>
    <geom name="floor" type="plane" size="6 6 0.1"/>
    <body name="wall" pos="1.0 0 0.75"><geom type="box" size="0.1 2 0.75"/></body>
    <body name="back_wall" pos="-2.6 0 0.75"><geom type="box" size="0.1 2 0.75"/><geom type="box" pos="0 2 0" size="1 0.1 0.75"/></body>
    <body name="far_shelf" pos="40 40 0.5"><geom type="box" size="0.3 0.3 0.5"/></body>
    <body pos="0 2.5 0.5"><geom type="box" size="0.3 0.3 0.5"/></body>
    <body name="walker" mocap="true" pos="0.5 0.6 0.9"><geom type="capsule" size="0.2 0.7"/></body>
  </worldbody>
</mujoco>)";

// Whether the pair of bodies a, b is excluded from colliding.
bool excluded(const mjModel* m, const char* a, const char* b) {
  int i = mj_name2id(m, mjOBJ_BODY, a), j = mj_name2id(m, mjOBJ_BODY, b);
  if (i > j) std::swap(i, j);
  for (int e = 0; e < m->nexclude; ++e)
    if (m->exclude_signature[e] == ((i + 1) << 16) + j + 1) return true;
  return false;
}

TEST(StaticExcludes, SamePhysicsAsTheWorldAsWritten) {
  const test::WorldFile file("walled.xml", kWalledRobotWorld);
  World world = World::from_file(file.path());
  char error[1000] = "";
  std::unique_ptr<mjModel, test::MjModelDeleter> plain(mj_loadXML(file.path().c_str(), nullptr, error, sizeof error));
  ASSERT_TRUE(plain) << error;
  std::unique_ptr<mjData, test::MjDataDeleter> data(mj_makeData(plain.get()));
  // The static bodies near each other and the world body with each; the far shelf is far from the walls, and the
  // unnamed box cannot be named.
  const mjModel* m = world.model();
  EXPECT_EQ(plain->nexclude, 0);
  EXPECT_TRUE(excluded(m, "wall", "back_wall"));
  EXPECT_TRUE(excluded(m, "world", "wall"));
  EXPECT_TRUE(excluded(m, "world", "far_shelf"));
  EXPECT_FALSE(excluded(m, "wall", "far_shelf"));
  EXPECT_FALSE(excluded(m, "wall", "base_link"));  // the robot moves: never excluded
  ASSERT_EQ(m->nbody, plain->nbody);
  ASSERT_EQ(m->nq, plain->nq);
  mj_forward(plain.get(), data.get());
  int contacts = 0;
  for (int step = 0; step < 1500; ++step) {
    const double left = step < 900 ? 15.0 : -10.0, right = step < 900 ? 15.0 : 10.0;
    world.data()->ctrl[0] = data->ctrl[0] = left;
    world.data()->ctrl[1] = data->ctrl[1] = right;
    world.step();
    mj_step2(plain.get(), data.get());
    mj_step1(plain.get(), data.get());
    ASSERT_EQ(world.data()->ncon, data->ncon) << "step " << step;
    ASSERT_EQ(std::memcmp(world.data()->qpos, data->qpos, sizeof(mjtNum) * m->nq), 0) << "step " << step;
    ASSERT_EQ(std::memcmp(world.data()->qvel, data->qvel, sizeof(mjtNum) * m->nv), 0) << "step " << step;
    for (int c = 0; c < data->ncon; ++c) {
      ASSERT_EQ(world.data()->contact[c].geom1, data->contact[c].geom1);
      ASSERT_EQ(world.data()->contact[c].geom2, data->contact[c].geom2);
      ASSERT_EQ(std::memcmp(world.data()->contact[c].pos, data->contact[c].pos, sizeof(mjtNum) * 3), 0);
      for (const int g : {data->contact[c].geom1, data->contact[c].geom2})
        contacts += m->geom_bodyid[g] == mj_name2id(m, mjOBJ_BODY, "wall");
    }
  }
  EXPECT_GT(contacts, 0);  // the robot pushed against the wall: the contacts compared include the walls'
}

TEST(StaticExcludes, NoneWithoutActuatorsOrForPredefinedPairsOnly) {
  // Without an actuator the compiler's fusestatic may have merged static bodies, which an <exclude> would stop.
  const test::WorldFile boxes("boxes.xml", R"(<mujoco><worldbody><geom type="plane" size="5 5 0.1"/>
    <body name="a" pos="1 0 0.5"><geom type="box" size="0.5 0.5 0.5"/></body>
    <body name="b" pos="1.5 0 0.5"><geom type="box" size="0.5 0.5 0.5"/></body></worldbody></mujoco>)");
  EXPECT_EQ(World::from_file(boxes.path()).model()->nexclude, 0);
  std::string predefined = kWalledRobotWorld;
  predefined.replace(predefined.find("<option "), 8, "<option collision=\"predefined\" ");
  const test::WorldFile pairs("pairs.xml", predefined);
  EXPECT_EQ(World::from_file(pairs.path()).model()->nexclude, 0);
  // An exclusion the world already has stays as it is, once.
  std::string own = kWalledRobotWorld;
  own.replace(own.rfind("</mujoco>"), 9, "<contact><exclude body1=\"wall\" body2=\"back_wall\"/></contact></mujoco>");
  const test::WorldFile with_own("own.xml", own);
  const World world = World::from_file(with_own.path());
  EXPECT_TRUE(excluded(world.model(), "wall", "back_wall"));
  EXPECT_TRUE(excluded(world.model(), "world", "wall"));
}

}  // namespace
}  // namespace stvl::sim

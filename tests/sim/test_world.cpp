#include <gmock/gmock.h>
#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <cstddef>
#include <cstring>
#include <stdexcept>

#include "sim/mocap_script.hpp"
#include "sim/simulator.hpp"
#include "sim/world.hpp"
#include "tests/support/fixture.hpp"
#include "truth/ground_truth.hpp"

namespace stvl::sim {
namespace {

using ::testing::HasSubstr;

std::string load_error(const std::string& xml) {
  try {
    World::from_string(xml);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(World, CompileErrorCarriesMujocoMessage) {
  const std::string error = load_error(R"(<mujoco><worldbody><geom type="sphere" size="-1"/></worldbody></mujoco>)");
  EXPECT_THAT(error, HasSubstr("cannot load world"));
  EXPECT_THAT(error, HasSubstr("size"));
}

TEST(World, XmlSyntaxErrorCarriesMujocoMessage) {
  const std::string error = load_error("<mujoco><worldbody></mujoco>");
  EXPECT_THAT(error, HasSubstr("XML"));
}

TEST(World, UnknownAttributeIsReported) {
  const std::string error = load_error(R"(<mujoco><worldbody><geom type="box" sise="1 1 1"/></worldbody></mujoco>)");
  EXPECT_THAT(error, HasSubstr("sise"));
}

TEST(World, MissingFileNamesPath) {
  try {
    World::from_file("/nonexistent/dir/world.xml");
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/dir/world.xml"));
  }
}

TEST(World, MissingIncludeNamesFile) {
  const std::string error = load_error(R"(<mujoco><include file="no_such_robot.xml"/></mujoco>)");
  EXPECT_THAT(error, HasSubstr("no_such_robot.xml"));
}

TEST(World, EmptyStringAndBadBaseDirThrow) {
  EXPECT_THROW(World::from_string(""), std::invalid_argument);
  EXPECT_THROW(World::from_string("<mujoco/>", "/nonexistent/base"), std::runtime_error);
}

TEST(World, LoadsStringWithIncludeAndIsMovable) {
  World world = World::from_string(test::kFlatWorld, test::worlds_dir());
  EXPECT_GT(world.model()->nbody, 3);
  EXPECT_DOUBLE_EQ(world.timestep_s(), 0.002);
  World moved = std::move(world);
  moved.step();
  EXPECT_NEAR(moved.time_s(), 0.002, 1e-12);
  EXPECT_GE(moved.body_id("base_link"), 1);
  EXPECT_THROW(moved.body_id("no_such_body"), std::invalid_argument);
}

// A snapshot takes the state as mj_copyData does, but not the scratch stack: every scalar before the buffer and
// every byte of the buffer (positions, poses, contacts) as mj_copyData gives them. (Stepped on, a copy would not
// follow its world exactly without the stack's leftovers, which MuJoCo 2.2.2's split step reads; snapshots are
// for reading.)
TEST(World, SnapshotTakesTheWholeState) {
  World world = World::from_string(test::kFlatWorld, test::worlds_dir());
  for (int i = 0; i < 200; ++i) world.step();  // the robot settles on its wheels: contacts
  World snapshot = world.copy();
  for (int i = 0; i < 50; ++i) world.step();
  snapshot.copy_state_from(world);
  const mjData* d = world.data();
  const mjData* s = snapshot.data();
  ASSERT_GT(d->ncon, 0);
  EXPECT_EQ(s->ncon, d->ncon);
  EXPECT_EQ(s->time, d->time);
  EXPECT_EQ(std::memcmp(s->buffer, d->buffer, static_cast<std::size_t>(world.model()->nbuffer)), 0);
  mjData* full = mj_makeData(world.model());
  mj_copyData(full, world.model(), d);
  EXPECT_EQ(std::memcmp(s, full, offsetof(mjData, buffer)), 0);
  EXPECT_EQ(std::memcmp(s->buffer, full->buffer, static_cast<std::size_t>(world.model()->nbuffer)), 0);
  mj_deleteData(full);
  for (int g = 0; g < 3 * world.model()->ngeom; ++g) EXPECT_EQ(s->geom_xpos[g], d->geom_xpos[g]);
  for (int c = 0; c < d->ncon; ++c) EXPECT_EQ(s->contact[c].geom1, d->contact[c].geom1);
  const World other = World::from_string("<mujoco><worldbody><geom type='sphere' size='1'/></worldbody></mujoco>");
  EXPECT_THROW(snapshot.copy_state_from(other), std::invalid_argument);
}

TEST(World, RobotGeomsAreAllInGroupTwo) {
  World world = World::from_string(test::kFlatWorld, test::worlds_dir());
  const mjModel* m = world.model();
  const int base = world.body_id("base_link");
  for (int g = 0; g < m->ngeom; ++g) {
    int b = m->geom_bodyid[g];
    while (b != 0 && b != base) b = m->body_parentid[b];
    if (b == base) {
      EXPECT_EQ(m->geom_group[g], 2) << "geom " << g;
    }
  }
}

// robot.geoms_seen_by_cameras: the named robot geoms move to group 3 (drawn by the renderer), ground truth still
// skips them (and the rest of the robot); other geoms and unknown names are errors.
TEST(World, ShowsChosenRobotGeomsToCamerasOnly) {
  World world = World::from_string(test::kFlatWorld, test::worlds_dir());
  const mjModel* m = world.model();
  const int bumper = world.geom_id("front_bumper"), mast = world.geom_id("mast");
  EXPECT_EQ(m->geom_group[bumper], kRobotGeomGroup);
  world.show_robot_geoms_to_cameras({"front_bumper"});
  EXPECT_EQ(m->geom_group[bumper], kRobotSeenGeomGroup);
  EXPECT_EQ(m->geom_group[mast], kRobotGeomGroup);
  world.show_robot_geoms_to_cameras({"front_bumper"});  // again: still seen
  EXPECT_EQ(m->geom_group[bumper], kRobotSeenGeomGroup);
  for (const auto& g : truth::obstacle_geoms(world)) EXPECT_NE(g.geom_id, bumper);
  EXPECT_THAT([&] { world.show_robot_geoms_to_cameras({"no_such_geom"}); },
              ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("no_such_geom")));
  EXPECT_THAT([&] { world.show_robot_geoms_to_cameras({"floor"}); },
              ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("not the robot's")));
}

const char* kMocapWorld = R"(
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="10 10 0.1"/>
    <body name="person" mocap="true" pos="1 0 0.9">
      <geom type="capsule" size="0.2 0.6"/>
    </body>
    <body name="crate" pos="3 0 0.5"><geom type="box" size="0.2 0.2 0.2"/></body>
  </worldbody>
</mujoco>)";

TEST(MocapScript, MovesBodyThroughKeyframes) {
  World world = World::from_string(kMocapWorld);
  const MocapScript script(world, {{"person", {{1.0, {1, 0, 0.9}, 0.0}, {3.0, {1, 6, 0.9}, 1.5}}}});
  const int body = world.body_id("person");
  auto pos_at = [&](double t) {
    script.apply(world.model(), world.data(), t);
    world.forward();
    return Eigen::Vector3d(world.data()->xpos[3 * body], world.data()->xpos[3 * body + 1],
                           world.data()->xpos[3 * body + 2]);
  };
  EXPECT_TRUE(pos_at(0.0).isApprox(Eigen::Vector3d(1, 0, 0.9)));
  EXPECT_TRUE(pos_at(2.0).isApprox(Eigen::Vector3d(1, 3, 0.9)));
  EXPECT_TRUE(pos_at(3.0).isApprox(Eigen::Vector3d(1, 6, 0.9)));
  EXPECT_TRUE(pos_at(10.0).isApprox(Eigen::Vector3d(1, 6, 0.9)));
  const double w = world.data()->xquat[4 * body], z = world.data()->xquat[4 * body + 3];
  EXPECT_NEAR(2 * std::atan2(z, w), 1.5, 1e-9);
}

TEST(MocapScript, RepeatingTrackAtTPlusPeriodEqualsT) {
  World world = World::from_string(kMocapWorld);
  const double period_s = 6.0;  // keyframes span 4 s; the last 2 s walk back to the first keyframe
  const MocapScript script(
      world, {{"person", {{1.0, {1, 0, 0.9}, 0.0}, {3.0, {1, 6, 0.9}, 1.5}, {5.0, {3, 6, 0.9}, 1.5}}, period_s}});
  const int body = world.body_id("person");
  auto pose_at = [&](double t) {
    script.apply(world.model(), world.data(), t);
    world.forward();
    Eigen::Matrix<double, 7, 1> pose;
    for (int i = 0; i < 3; ++i) pose[i] = world.data()->xpos[3 * body + i];
    for (int i = 0; i < 4; ++i) pose[3 + i] = world.data()->xquat[4 * body + i];
    return pose;
  };
  EXPECT_TRUE(pose_at(0.0).head<3>().isApprox(Eigen::Vector3d(1, 0, 0.9)));  // held before the first keyframe
  EXPECT_TRUE(pose_at(6.0).head<3>().isApprox(Eigen::Vector3d(2, 3, 0.9)));  // half way back from the last
  EXPECT_TRUE(pose_at(7.0).head<3>().isApprox(Eigen::Vector3d(1, 0, 0.9)));  // the first again at t0 + period
  for (double t = 1.0; t < 8.0; t += 0.37)
    for (int k = 1; k <= 3; ++k)
      EXPECT_LT((pose_at(t + k * period_s) - pose_at(t)).norm(), 1e-9) << "t " << t << ", lap " << k;
}

TEST(MocapScript, RejectsBadTracks) {
  World world = World::from_string(kMocapWorld);
  EXPECT_THROW(MocapScript(world, {{"nobody", {{0.0, {0, 0, 0}, {}}}}}), std::invalid_argument);
  EXPECT_THROW(MocapScript(world, {{"crate", {{0.0, {0, 0, 0}, {}}}}}), std::invalid_argument);
  EXPECT_THROW(MocapScript(world, {{"person", {}}}), std::invalid_argument);
  EXPECT_THROW(MocapScript(world, {{"person", {{1.0, {0, 0, 0}, {}}, {1.0, {1, 0, 0}, {}}}}}), std::invalid_argument);
  EXPECT_THROW(MocapScript(world, {{"person", {{0.0, {0, 0, 0}, 0.0}, {1.0, {1, 0, 0}, {}}}}}), std::invalid_argument);
  const std::vector<MocapKeyframe> walk{{1.0, {0, 0, 0}, {}}, {4.0, {1, 0, 0}, {}}};
  EXPECT_THROW(MocapScript(world, {{"person", walk, 2.9}}), std::invalid_argument);  // shorter than the 3 s span
  EXPECT_THROW(MocapScript(world, {{"person", walk, NAN}}), std::invalid_argument);
  EXPECT_THROW(MocapScript(world, {{"person", {{1.0, {0, 0, 0}, {}}}, 0.0}}), std::invalid_argument);
  EXPECT_NO_THROW(MocapScript(world, {{"person", walk, 3.0}}));
  try {
    MocapScript(world, {{"nobody", {{0.0, {0, 0, 0}, {}}}}});
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("nobody"));
  }
}

TEST(World, ExtentCoversFinitePlanesAndGeomsButNotTheRobotOrInfinitePlanes) {
  const World world = World::from_string(R"(
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" pos="10 1 0" size="12 3 0.1"/>
    <geom name="sky" type="plane" pos="0 0 5" size="0 0 0.1"/>
    <geom name="pillar" type="sphere" pos="30 0 1" size="0.5"/>
    <geom name="robot_part" type="box" pos="-40 0 0" size="1 1 1" group="2"/>
  </worldbody>
</mujoco>)");
  const Eigen::AlignedBox2d e = world.extent_xy();
  EXPECT_DOUBLE_EQ(e.min().x(), -2.0);  // the floor from 10 - 12
  EXPECT_DOUBLE_EQ(e.min().y(), -2.0);
  EXPECT_DOUBLE_EQ(e.max().x(), 30.5);  // the sphere's bound
  EXPECT_DOUBLE_EQ(e.max().y(), 4.0);
  EXPECT_TRUE(World::from_string("<mujoco><worldbody><geom type=\"plane\" size=\"0 0 1\"/></worldbody></mujoco>")
                  .extent_xy()
                  .isEmpty());
}

// The fixture's warning handler is installed (tests/support/fixture.hpp): a MuJoCo warning fails the test, or
// inside an ExpectMujocoWarning is counted there.
TEST(MujocoFixture, WarningsFailTheTestUnlessExpected) {
  EXPECT_NONFATAL_FAILURE(mju_warning("stvl test warning"), "MuJoCo warning: stvl test warning");
  test::ExpectMujocoWarning expected;
  mju_warning("stvl test warning");
  EXPECT_EQ(expected.count(), 1);
}

}  // namespace
}  // namespace stvl::sim

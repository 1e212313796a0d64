#include <gtest/gtest.h>

#include <set>
#include <string>

#include "sim/simulator.hpp"
#include "tests/support/fixture.hpp"
#include "truth/ground_truth.hpp"

namespace stvl::sim {
namespace {

// Robot geoms touching anything but the floor, by body name of the other geom.
std::set<std::string> robot_collisions(const World& world, int floor_geom) {
  std::set<std::string> hits;
  const mjModel* m = world.model();
  const mjData* d = world.data();
  for (int i = 0; i < d->ncon; ++i) {
    const int g1 = d->contact[i].geom1, g2 = d->contact[i].geom2;
    const bool robot1 = m->geom_group[g1] == 2, robot2 = m->geom_group[g2] == 2;
    if (robot1 == robot2) continue;
    const int other = robot1 ? g2 : g1;
    if (other != floor_geom) hits.insert(world.body_name(m->geom_bodyid[other]));
  }
  return hits;
}

struct Drive {
  bool finished = false;
  double max_cross_track_m = 0, max_tilt_rad = 0;
  std::set<std::string> collisions;
};

Drive drive(Simulator& sim, const Path& path, double timeout_s) {
  const int floor = sim.world().geom_id("floor");
  sim.set_path(path);
  Drive r;
  while (!sim.path_finished() && sim.time_s() < timeout_s) {
    sim.step();
    r.max_cross_track_m =
        std::max(r.max_cross_track_m, sim.follower().cross_track_error_m(sim.T_world_base().translation().head<2>()));
    r.max_tilt_rad = std::max(r.max_tilt_rad, sim.robot().tilt_rad());
    const auto c = robot_collisions(sim.world(), floor);
    r.collisions.insert(c.begin(), c.end());
  }
  r.finished = sim.path_finished();
  return r;
}

std::set<std::string> obstacle_bodies(const World& world) {
  std::set<std::string> names;
  for (const auto& g : truth::obstacle_geoms(world)) names.insert(g.body_name);
  return names;
}

TEST(ShippedWorlds, OfficeCorridorHasNamedObstacles) {
  World world = World::from_file(test::worlds_dir() + "/office_corridor.xml");
  const auto names = obstacle_bodies(world);
  for (const char* name : {"desk_1", "cabinet_1", "shelf_1", "box_1", "fire_extinguisher", "person"}) {
    EXPECT_TRUE(names.count(name)) << name;
  }
  EXPECT_GE(world.model()->body_mocapid[world.body_id("person")], 0);
  EXPECT_DOUBLE_EQ(world.timestep_s(), 0.002);
  EXPECT_EQ(world.model()->vis.quality.offsamples, 0);
}

TEST(ShippedWorlds, DriveFiveMetersDownOfficeCorridor) {
  Simulator sim(World::from_file(test::worlds_dir() + "/office_corridor.xml"));
  const Drive r = drive(sim, {{{0, 0}, {5, 0}}, 0.8}, 30.0);
  EXPECT_TRUE(r.finished);
  EXPECT_LT(r.max_cross_track_m, 0.05);
  EXPECT_LT(r.max_tilt_rad, 0.05);
  EXPECT_TRUE(r.collisions.empty()) << *r.collisions.begin();
  EXPECT_NEAR(sim.T_world_base().translation().x(), 5.0, 0.06);
}

TEST(ShippedWorlds, DriveWholeOfficeCorridorWhilePersonWalksAway) {
  Simulator sim(World::from_file(test::worlds_dir() + "/office_corridor.xml"));
  const Eigen::Vector3d start(sim.world().data()->xpos + 3 * sim.world().body_id("person"));
  sim.set_mocap_tracks({{"person", {{2.0, start, 0.0}, {8.0, start + Eigen::Vector3d(6, 0, 0), 0.0}}}});
  const Drive r = drive(sim, {{{0, 0}, {22, 0}}, 1.0}, 60.0);
  EXPECT_TRUE(r.finished);
  EXPECT_LT(r.max_cross_track_m, 0.05);
  EXPECT_TRUE(r.collisions.empty()) << *r.collisions.begin();
}

TEST(ShippedWorlds, PersonWalksAway) {
  Simulator sim(World::from_file(test::worlds_dir() + "/office_corridor.xml"));
  const int person = sim.world().body_id("person");
  const Eigen::Vector3d start(sim.world().data()->xpos + 3 * person);
  sim.set_mocap_tracks({{"person", {{0.5, start, {}}, {4.5, start + Eigen::Vector3d(6, 0, 0), {}}}}});
  sim.run_until(5.0);
  const Eigen::Vector3d end(sim.world().data()->xpos + 3 * person);
  EXPECT_TRUE(end.isApprox(start + Eigen::Vector3d(6, 0, 0), 1e-9));
}

TEST(ShippedWorlds, LCorridorThroughTheTurn) {
  World world = World::from_file(test::worlds_dir() + "/l_corridor.xml");
  const auto names = obstacle_bodies(world);
  for (const char* name : {"chair", "trash_bin", "plant_pot", "sliding_door", "doorway_frame"}) {
    EXPECT_TRUE(names.count(name)) << name;
  }
  EXPECT_GE(world.model()->body_mocapid[world.body_id("sliding_door")], 0);
  Simulator sim(std::move(world));
  const Drive r = drive(sim, {{{0, 0}, {8, 0}, {8, 7}}, 0.7}, 60.0);
  EXPECT_TRUE(r.finished);
  EXPECT_LT(r.max_cross_track_m, 0.1);
  EXPECT_LT(r.max_tilt_rad, 0.05);
  EXPECT_TRUE(r.collisions.empty()) << *r.collisions.begin();
  EXPECT_NEAR(sim.T_world_base().translation().y(), 7.0, 0.06);
}

TEST(ShippedWorlds, CorridorVoxelizationInHeightBand) {
  World world = World::from_file(test::worlds_dir() + "/office_corridor.xml");
  truth::VoxelizeOptions options;
  options.voxel_size_m = 0.1;
  options.bounds_W = Eigen::AlignedBox3d(Eigen::Vector3d(-2, -3, 0.11), Eigen::Vector3d(30, 3, 1.99));
  const auto bodies = truth::voxelize_bodies(truth::obstacle_geoms(world), options);
  std::size_t total = 0;
  for (const auto& b : bodies) {
    total += b.voxels.size();
    for (const auto& k : b.voxels) {
      ASSERT_GE(k.z, 1) << b.body_name;
      ASSERT_LE(k.z, 19) << b.body_name;
    }
  }
  EXPECT_GT(total, 5000u);
  EXPECT_EQ(bodies.size(), 22u);
}

}  // namespace
}  // namespace stvl::sim

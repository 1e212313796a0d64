// The office generator: one seed one world (byte for byte), worlds MuJoCo loads without a warning with every
// obstacle a named body of primitive geoms, a path clear of everything on the inflated grid, people who never
// walk where the robot could be, and a scenario that loads with its mocap tracks.
#include "worldgen/office_generator.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "config/scenario.hpp"
#include "pipeline/pipeline.hpp"
#include "tests/support/fixture.hpp"
#include "tests/worldgen/helpers.hpp"
#include "worldgen/map_world.hpp"

namespace stvl::worldgen {
namespace {

double robot_radius() {
  static const double radius = robot_footprint_radius_m(shipped_robot_xml());
  return radius;
}

OfficeWorld office(std::uint64_t seed, int people = 3) {
  OfficeOptions o;
  o.seed = seed;
  o.people = people;
  return generate_office(o, robot_radius());
}

TEST(OfficeGenerator, OneSeedOneWorldByteForByte) {
  OfficeOptions o;
  o.seed = 7;
  const OfficeWorld a = generate_office(o, robot_radius()), b = generate_office(o, robot_radius());
  EXPECT_EQ(write_mjcf(a.spec), write_mjcf(b.spec));
  EXPECT_EQ(office_scenario_yaml(a, o, "x", "world.xml"), office_scenario_yaml(b, o, "x", "world.xml"));
  o.seed = 8;
  const OfficeWorld c = generate_office(o, robot_radius());
  EXPECT_NE(write_mjcf(a.spec), write_mjcf(c.spec));
}

TEST(OfficeGenerator, WorldsLoadWithoutWarningsAndEveryObstacleIsANamedPrimitive) {
  const std::set<int> primitives{mjGEOM_BOX, mjGEOM_CYLINDER, mjGEOM_SPHERE, mjGEOM_CAPSULE, mjGEOM_ELLIPSOID};
  for (std::uint64_t seed : {1, 2, 3, 4}) {
    const OfficeWorld w = office(seed);
    const stvl::test::MjWorld world(write_mjcf(w.spec), stvl::test::worlds_dir());  // a MuJoCo warning fails the test
    const mjModel* m = world.model();
    std::set<std::string> kinds;
    for (int g = 0; g < m->ngeom; ++g) {
      const int group = m->geom_group[g];
      if (group == 2 || group == 3) continue;  // the robot's
      const int body = m->geom_bodyid[g];
      if (body == 0) {
        EXPECT_EQ(m->geom_type[g], mjGEOM_PLANE);  // only the floor belongs to the world body
        continue;
      }
      const std::string name = mj_id2name(m, mjOBJ_BODY, body);
      EXPECT_TRUE(primitives.count(m->geom_type[g])) << name;
      const bool wall = name == "walls" || name.rfind("door_", 0) == 0;
      EXPECT_EQ(group, wall ? 0 : 1) << name;
      kinds.insert(name.substr(0, name.find('_')));
    }
    EXPECT_TRUE(kinds.count("desk") && kinds.count("person") && kinds.count("extinguisher") && kinds.count("door"))
        << seed;
    EXPECT_GT(w.path.length_m, 12.0) << w.summary;
    EXPECT_LT(w.path.length_m, 30.0) << w.summary;
  }
}

TEST(OfficeGenerator, PathIsClearOfEverythingOnTheInflatedGrid) {
  for (std::uint64_t seed : {1, 2, 3, 4, 5, 6}) {
    const OfficeWorld w = office(seed);
    const auto& p = w.path.waypoints_W;
    EXPECT_NEAR(w.drive.radius_m, robot_radius() + kPathMarginM, 1e-12);
    for (std::size_t i = 1; i < p.size(); ++i)
      EXPECT_TRUE(w.drive.segment_clear(p[i - 1], p[i], w.drive.radius_m)) << "seed " << seed << " leg " << i;
    for (std::size_t i = 1; i < p.size(); ++i)
      for (int k = 0; k <= 50; ++k)
        EXPECT_GE(test::distance_to_occupied(w.grid, p[i - 1] + (p[i] - p[i - 1]) * (k / 50.0)), robot_radius())
            << seed;
  }
}

// Where a keyframed body is at time t (held before the first and after the last keyframe).
Eigen::Vector2d position_at(const MovingBodySpec& m, double t) {
  const auto& k = m.keyframes;
  if (t <= k.front().t_s) return k.front().position_W.head<2>();
  for (std::size_t i = 1; i < k.size(); ++i)
    if (t <= k[i].t_s) {
      const double u = (t - k[i - 1].t_s) / (k[i].t_s - k[i - 1].t_s);
      return (k[i - 1].position_W + u * (k[i].position_W - k[i - 1].position_W)).head<2>();
    }
  return k.back().position_W.head<2>();
}

TEST(OfficeGenerator, PeopleNeverWalkWhereTheRobotCouldBe) {
  // At time t the robot is somewhere on the first speed * t metres of its path (it never goes faster): no walking
  // person may come within their 0.3 m and the robot's radius of that stretch.
  for (std::uint64_t seed : {1, 2, 3, 4, 5, 6, 7, 8}) {
    const OfficeWorld w = office(seed, 6);
    const auto& p = w.path.waypoints_W;
    EXPECT_FALSE(w.walks.empty()) << seed;
    for (const MovingBodySpec& m : w.walks)
      for (double t = 0; t <= m.keyframes.back().t_s + 0.5; t += 0.1) {
        const Eigen::Vector2d person = position_at(m, t);
        double reach = 0.6 * t + 0.05;
        for (std::size_t i = 1; i < p.size() && reach > 0; ++i) {
          const double len = (p[i] - p[i - 1]).norm(), part = std::min(len, reach);
          for (double s = 0; s <= part; s += 0.05)
            ASSERT_GE((p[i - 1] + (p[i] - p[i - 1]) * (s / len) - person).norm(), 0.3 + robot_radius())
                << "seed " << seed << " " << m.body << " at t = " << t;
          reach -= len;
        }
      }
  }
}

TEST(OfficeGenerator, ScenarioLoadsAndItsTracksFitTheWorld) {
  test::TempDir dir;
  const OfficeOptions o;
  const OfficeWorld w = generate_office(o, robot_radius());
  dir.write("world.xml", write_mjcf(w.spec));
  std::filesystem::copy_file(shipped_robot_xml(), dir.path() / "robot.xml");
  const std::string yaml = dir.write("scenario.yaml", office_scenario_yaml(w, o, "generated", "world.xml"));
  const config::Scenario s = config::load_scenario(yaml);
  EXPECT_EQ(s.name, "generated");
  EXPECT_EQ(s.pipeline.path.waypoints_W.size(), w.path.waypoints_W.size());
  EXPECT_EQ(s.pipeline.moving_bodies.size(), w.walks.size());
  EXPECT_GT(s.duration_s, w.path.length_m / o.speed_mps);
  EXPECT_TRUE(s.stop_at_path_end);
  EXPECT_NO_THROW(pipeline::make_simulator(s.pipeline));  // the mocap bodies exist and the tracks are valid
}

TEST(OfficeGenerator, OptionsOutOfRangeAreErrors) {
  OfficeOptions o;
  o.width_m = 5;
  EXPECT_THROW(generate_office(o, robot_radius()), std::invalid_argument);
  o = OfficeOptions{};
  o.people = 21;
  EXPECT_THROW(generate_office(o, robot_radius()), std::invalid_argument);
  o = OfficeOptions{};
  o.wall_height_m = 2.0;
  EXPECT_THROW(generate_office(o, robot_radius()), std::invalid_argument);
  o = OfficeOptions{};
  o.width_m = 40, o.height_m = 25, o.people = 8;
  EXPECT_NO_THROW(generate_office(o, robot_radius()));
}

}  // namespace
}  // namespace stvl::worldgen

// Worlds from nav2 maps: walls where the occupied cells are (origin yaw included), exactly those cells in few
// boxes, loaded by MuJoCo without a warning, and a scenario beside them that loads.
#include "worldgen/map_world.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "tests/support/fixture.hpp"
#include "tests/worldgen/helpers.hpp"
#include "worldgen/scenario_writer.hpp"

namespace stvl::worldgen {
namespace {

using test::TempDir;

const std::string kOfficeFloor = std::string(STVL_SOURCE_DIR) + "/worlds/maps/office_floor.yaml";

// Distance down to the first geom of group 0 from (x, y, 5 m) (walls and the floor).
double drop_to_group0(const stvl::test::MjWorld& world, double x, double y) {
  const mjtNum from[3] = {x, y, 5.0}, down[3] = {0, 0, -1};
  const mjtByte groups[mjNGROUP] = {1, 0, 0, 0, 0, 0};
  int geom = -1;
  return mj_ray(world.model(), world.data(), from, down, groups, 1, -1, &geom);
}

TEST(MapWorld, OriginYawPutsAWallWhereTheCellIs) {
  TempDir dir;
  // 4 x 3 pixels of 0.5 m, one black: image column 2 of the top row, map cell (2, 2).
  dir.write("m.pgm", test::pgm_p5(4, 3, {254, 254, 0, 254, 254, 254, 254, 254, 254, 254, 254, 254}));
  const std::string yaml = dir.write("m.yaml", test::map_yaml("m.pgm", 0.5, "[1.0, -1.0, 1.5707963267948966]"));
  const MapWorld w = build_map_world(yaml, 2.0);
  ASSERT_EQ(w.wall_boxes, 1u);
  const Geom& g = w.spec.bodies.front().geoms.front();
  // The cell's centre (1.25, 1.25) in the map's frame, turned a quarter about the origin (1, -1): (-0.25, 0.25).
  EXPECT_NEAR(g.pos.x(), -0.25, 1e-9);
  EXPECT_NEAR(g.pos.y(), 0.25, 1e-9);
  EXPECT_NEAR(g.pos.z(), 1.0, 1e-9);
  EXPECT_NEAR(g.yaw_rad, M_PI / 2, 1e-12);
  const stvl::test::MjWorld world(write_mjcf(w.spec), stvl::test::worlds_dir());
  EXPECT_NEAR(drop_to_group0(world, -0.25, 0.25), 3.0, 1e-6);  // the wall's top, 2 m high
  EXPECT_NEAR(drop_to_group0(world, -0.25, 0.55), 5.0, 1e-6);  // beside it: the floor
}

TEST(MapWorld, WallBoxesAreExactlyTheOccupiedCellsOfTheShippedMap) {
  const MapWorld w = build_map_world(kOfficeFloor, 2.5);
  const GridFrame& f = w.grid.frame;
  std::set<std::size_t> covered;
  for (const Geom& g : w.spec.bodies.front().geoms) {
    EXPECT_EQ(g.type, "box");
    EXPECT_EQ(g.group, kWallGroup);
    const Eigen::Vector2d lo =
        f.to_grid(g.pos.head<2>()) / f.resolution_m - Eigen::Vector2d(g.size[0], g.size[1]) / f.resolution_m;
    const int cols = static_cast<int>(std::lround(2 * g.size[0] / f.resolution_m)),
              rows = static_cast<int>(std::lround(2 * g.size[1] / f.resolution_m));
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c)
        EXPECT_TRUE(
            covered
                .insert(f.index({static_cast<int>(std::lround(lo.x())) + c, static_cast<int>(std::lround(lo.y())) + r}))
                .second);
  }
  std::size_t occupied = 0;
  for (std::size_t i = 0; i < w.grid.cells.size(); ++i) {
    occupied += w.grid.cells[i] == Cell::kOccupied;
    EXPECT_EQ(covered.count(i), w.grid.cells[i] == Cell::kOccupied ? 1u : 0u) << i;
  }
  EXPECT_GT(occupied, 1000u);
  EXPECT_LT(w.wall_boxes, 40u);  // 20 x 120 cells of walls in about twenty boxes
  EXPECT_EQ(std::count(w.grid.cells.begin(), w.grid.cells.end(), Cell::kUnknown),
            26 * 20);                                                             // the corner not yet mapped
  const stvl::test::MjWorld world(write_mjcf(w.spec), stvl::test::worlds_dir());  // a MuJoCo warning fails the test
  int boxes = 0;
  for (int g = 0; g < world.model()->ngeom; ++g)
    boxes += world.model()->geom_group[g] == 0 && world.model()->geom_type[g] == mjGEOM_BOX;
  EXPECT_EQ(boxes, static_cast<int>(w.wall_boxes));
}

TEST(MapWorld, PlannedPathOnTheShippedMapIsCollisionFree) {
  const MapWorld w = build_map_world(kOfficeFloor, 2.5);
  const double radius = robot_footprint_radius_m(shipped_robot_xml());
  EXPECT_NEAR(radius, std::hypot(0.255, 0.14), 1e-3);  // the front bumper's outer corners
  const DriveGrid d = map_drive_grid(w, radius);
  const PlannedPath p = plan_path(d, w.grid.cells, std::nullopt, std::nullopt);
  for (std::size_t i = 1; i < p.waypoints_W.size(); ++i)
    EXPECT_TRUE(d.segment_clear(p.waypoints_W[i - 1], p.waypoints_W[i], d.radius_m));
  EXPECT_GT(p.length_m, 8.0);
  const std::string yaml = map_scenario_yaml(w, p, "floor", "world.xml");
  EXPECT_THAT(yaml, ::testing::HasSubstr("world: world.xml\n"));
  EXPECT_THAT(yaml, ::testing::HasSubstr("f1_3d_min: 0.9\n"));
}

TEST(MapWorld, WallHeightMustBeSensible) {
  EXPECT_THROW(build_map_world(kOfficeFloor, 0.0), std::invalid_argument);
  EXPECT_THROW(build_map_world(kOfficeFloor, std::nan("")), std::invalid_argument);
}

}  // namespace
}  // namespace stvl::worldgen

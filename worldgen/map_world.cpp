#include "worldgen/map_world.hpp"

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "worldgen/scenario_writer.hpp"

namespace stvl::worldgen {

MapWorld build_map_world(const std::string& map_yaml, double wall_height_m) {
  if (!(std::isfinite(wall_height_m) && wall_height_m > 0 && wall_height_m <= 10))
    throw std::invalid_argument("wall height " + fixed(wall_height_m, 3) + " m: must lie in (0, 10] m");
  MapWorld w;
  w.map_yaml = map_yaml;
  w.map = load_nav2_map(map_yaml);
  w.grid = occupancy_from_nav2(w.map);
  const GridFrame& f = w.grid.frame;
  const double res = f.resolution_m;
  w.spec.model_name = std::filesystem::path(map_yaml).stem().string();
  w.spec.comment =
      "Built by stvl-bench world from-map from " + std::filesystem::path(map_yaml).filename().string() + ": " +
      std::to_string(f.width) + " x " + std::to_string(f.height) + " cells of " + fixed(res, 3) + " m, origin [" +
      fixed(f.origin_x_m, 3) + ", " + fixed(f.origin_y_m, 3) + ", " + fixed(f.yaw_rad, 4) + "], mode " +
      to_string(w.map.meta.mode) + (w.map.meta.negate ? ", negated" : "") + ".\nEvery occupied cell is a wall " +
      fixed(wall_height_m, 2) + " m high; the cells are merged into boxes. Free and unknown cells are floor.";
  // The floor: the map's corners in the world, and a metre around them.
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (double gx : {0.0, f.width * res})
    for (double gy : {0.0, f.height * res}) {
      const Eigen::Vector2d p = f.to_world({gx, gy});
      lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    }
  w.spec.floor_min_W = lo - Eigen::Vector2d(1, 1);
  w.spec.floor_max_W = hi + Eigen::Vector2d(1, 1);
  Body walls;
  walls.name = "walls";
  walls.comment = "the occupied cells, merged into boxes";
  for (const CellRect& r : merge_occupied(w.grid)) {
    const Eigen::Vector2d c = f.to_world({(r.col + 0.5 * r.cols) * res, (r.row + 0.5 * r.rows) * res});
    walls.geoms.push_back({"box",
                           "",
                           Eigen::Vector3d(c.x(), c.y(), wall_height_m / 2),
                           {0.5 * r.cols * res, 0.5 * r.rows * res, wall_height_m / 2},
                           {},
                           f.yaw_rad,
                           kWallGroup,
                           "0.85 0.85 0.8 1"});
  }
  w.wall_boxes = walls.geoms.size();
  if (!walls.geoms.empty()) w.spec.bodies.push_back(walls);
  return w;
}

DriveGrid map_drive_grid(const MapWorld& world, double robot_radius_m) {
  return make_drive_grid(world.grid, robot_radius_m + kPathMarginM);
}

std::string map_scenario_yaml(const MapWorld& world, const PlannedPath& path, const std::string& name,
                              const std::string& world_file) {
  ScenarioSpec s;
  s.name = name;
  s.world_file = world_file;
  s.description =
      "The robot drives a world built from the nav2 map " + world.map_yaml +
      " (stvl-bench world from-map):\nthe occupied cells are walls, the path is planned through the free cells.";
  s.start = {path.waypoints_W.front().x(), path.waypoints_W.front().y(), path.start_yaw_rad * 180.0 / M_PI};
  s.waypoints_W = path.waypoints_W;
  return write_scenario_yaml(s);
}

}  // namespace stvl::worldgen

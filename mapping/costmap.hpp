#pragma once
// 2D costmap projected from the voxel map, and its export as a nav2 map_server image + YAML.
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace stvl::mapping {

// nav2_costmap_2d values.
constexpr std::uint8_t kCostFree = 0;
constexpr std::uint8_t kCostLethal = 254;
constexpr std::uint8_t kCostUnknown = 255;

struct CostmapOptions {
  double resolution_m = 0.0;                    // per cell; 0 = the map's voxel size
  std::optional<Eigen::AlignedBox2d> bounds_W;  // x/y extent; default: the occupied voxels' extent
  // Voxels count toward a column when their centre z lies in this band (inclusive).
  double min_obstacle_height_m = -std::numeric_limits<double>::infinity();
  double max_obstacle_height_m = std::numeric_limits<double>::infinity();
  // STVL's update_footprint_enabled: the cells of this polygon's convex fill (mapping/footprint.hpp) are set
  // free after the projection; the voxels stay. Empty: nothing is cleared.
  std::vector<Eigen::Vector2d> free_polygon_W;
};

// Cell (ix, iy) covers [origin_m.x + ix*resolution_m, +resolution_m) x [origin_m.y + iy*resolution_m, +resolution_m);
// cells are row-major with row 0 at the lowest y.
struct Costmap2D {
  int width = 0;
  int height = 0;
  double resolution_m = 0.05;
  Eigen::Vector2d origin_m = Eigen::Vector2d::Zero();  // world x, y of cell (0, 0)'s corner
  std::vector<std::uint8_t> cells;

  std::uint8_t at(int ix, int iy) const { return cells.at(static_cast<std::size_t>(iy) * width + ix); }
  // Cell holding the world point (x_m, y_m), or nullopt outside the grid.
  std::optional<std::uint8_t> at_world(double x_m, double y_m) const;
};

// Writes <base>.pgm (P5, lethal black 0, free white 254, unknown 205, top row = highest y) and <base>.yaml
// (image, resolution, origin [x, y, 0], negate 0, occupied_thresh 0.65, free_thresh 0.196, mode trinary).
// Each file is written to a temporary name and renamed. Throws std::runtime_error on I/O failure.
void write_costmap(const Costmap2D& costmap, const std::string& base_path);

}  // namespace stvl::mapping

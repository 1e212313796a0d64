#pragma once
// A planar occupancy grid placed in the world, its clearance (distance to the nearest occupied cell) and the
// robot's drivable cells, and the greedy merge of occupied cells into few rectangles (the walls of a map world).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "worldgen/nav2_map.hpp"

namespace stvl::worldgen {

enum class Cell : std::uint8_t { kFree = 0, kOccupied = 1, kUnknown = 2 };

struct CellIndex {
  int col = 0, row = 0;
  bool operator==(const CellIndex& o) const { return col == o.col && row == o.row; }
};

// Where the grid lies: cell (col, row) covers [col, col + 1) x [row, row + 1) cells in the grid's own frame,
// whose corner (0, 0) lies at origin_W, turned by yaw_rad about z (a nav2 map's origin [x, y, yaw]).
struct GridFrame {
  int width = 0, height = 0;
  double resolution_m = 0.05;
  double origin_x_m = 0, origin_y_m = 0, yaw_rad = 0;

  Eigen::Vector2d to_world(const Eigen::Vector2d& p_G) const;  // grid-frame metres -> world
  Eigen::Vector2d to_grid(const Eigen::Vector2d& p_W) const;   // world -> grid-frame metres
  Eigen::Vector2d cell_center_W(CellIndex c) const;
  // The cell holding p_W; empty outside the grid.
  std::optional<CellIndex> cell_of(const Eigen::Vector2d& p_W) const;
  bool contains(CellIndex c) const { return c.col >= 0 && c.row >= 0 && c.col < width && c.row < height; }
  std::size_t index(CellIndex c) const { return static_cast<std::size_t>(c.row) * width + c.col; }
  CellIndex cell(std::size_t index) const {
    return {static_cast<int>(index % static_cast<std::size_t>(width)),
            static_cast<int>(index / static_cast<std::size_t>(width))};
  }
};

struct OccupancyGrid {
  GridFrame frame;
  std::vector<Cell> cells;  // frame.index(c)
  Cell at(CellIndex c) const { return cells[frame.index(c)]; }
};

// A nav2 map's cells: 100 occupied (a wall), 0 free (drivable), anything else (-1 unknown, scale mode's 1..99)
// unknown: no wall, but not drivable either.
OccupancyGrid occupancy_from_nav2(const Nav2Map& map);

// An axis-aligned block of cells: columns col .. col + cols - 1, rows row .. row + rows - 1.
struct CellRect {
  int col = 0, row = 0, cols = 1, rows = 1;
};

// Greedy rectangle merge of the occupied cells (row by row from row 0, each run of unclaimed occupied cells
// widened as far as it goes along the row, then grown upwards while every cell under it is occupied and
// unclaimed): the rectangles are disjoint and cover exactly the occupied cells.
std::vector<CellRect> merge_occupied(const OccupancyGrid& grid);

// Per cell, the distance (m) from its centre to the nearest occupied cell's square, a lower bound: the exact
// Euclidean distance between cell centres (Felzenszwalb's transform) minus half a cell diagonal, at least 0;
// infinity when the grid holds no occupied cell. Occupied cells have 0.
std::vector<float> clearance_m(const OccupancyGrid& grid);

// Where the robot's centre may go: free cells whose clearance is at least radius_m (the robot's footprint radius
// plus a margin), so that a disc of radius_m around the centre touches no wall. Unknown cells are never drivable.
struct DriveGrid {
  GridFrame frame;
  double radius_m = 0;
  std::vector<float> clearance_m;
  std::vector<std::uint8_t> drivable;  // 1 drivable
  bool drivable_at(CellIndex c) const { return frame.contains(c) && drivable[frame.index(c)] != 0; }
  // Whether every point of the segment (sampled every quarter cell) lies in a drivable cell with at least
  // min_clearance_m of clearance.
  bool segment_clear(const Eigen::Vector2d& a_W, const Eigen::Vector2d& b_W, double min_clearance_m) const;
};
DriveGrid make_drive_grid(const OccupancyGrid& grid, double radius_m);

}  // namespace stvl::worldgen

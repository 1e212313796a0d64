#pragma once
// nav2's voxel grid (package nav2_voxel_grid, the grid under nav2_costmap_2d's VoxelLayer), with nav2's data and
// arithmetic: follows ros-navigation/navigation2 nav2_voxel_grid/include/nav2_voxel_grid/voxel_grid.hpp and
// src/voxel_grid.cpp at main a3a97043 (2026-08-21); jazzy f4108e5 (last change there ae6dcbc) and humble a097086
// behave the same (they differ in includes and a comment only).
//
// The grid is size_x x size_y columns of 32 bits; level z (0..15) of a column is the pair (bit z, bit z + 16):
//   low bit set, high bit clear: UNKNOWN (a new or reset column is 0x0000ffff: every level unknown, even levels at
//   and above size_z, which only clear_voxel_column changes; nav2's VoxelLayer adds 16 - z_voxels to
//   unknown_threshold); both set: MARKED (marking sets both bits); both clear: FREE (clearing clears both).
// A column's marked count is the popcount of its high half; its unknown count that of (high half XOR low half).
// Everything is in cells: x, y, z are cell coordinates (a line's endpoints are real-valued cell coordinates, nav2's
// worldToMap3DFloat), lengths are cells. Nothing here knows metres or the world frame.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <vector>

namespace stvl::layer::nav2 {

// nav2: VoxelStatus FREE = 0, UNKNOWN = 1, MARKED = 2.
enum class VoxelStatus { kFree = 0, kUnknown = 1, kMarked = 2 };

constexpr unsigned kMaxZCells = 16;                                      // levels a 32-bit column holds
constexpr unsigned kNoMaxLength = std::numeric_limits<unsigned>::max();  // nav2's default max_length, UINT_MAX
constexpr std::uint32_t kUnknownColumn = 0x0000ffffu;                    // every level unknown

// The popcount of n (nav2: numBits).
unsigned num_bits(std::uint32_t n);
// Whether n has at most threshold bits set (nav2: bitsBelowThreshold, which despite its name means "<=").
bool bits_at_most(std::uint32_t n, unsigned threshold);

class VoxelGrid {
 public:
  // A grid of size_x_cells x size_y_cells columns of size_z_cells levels, every voxel unknown. Throws
  // std::invalid_argument naming z_voxels when size_z_cells > 16 (nav2 logs and uses 16).
  VoxelGrid(unsigned size_x_cells, unsigned size_y_cells, unsigned size_z_cells);

  // New sizes, every voxel unknown (nav2: resize; the same sizes only reset). Throws as the constructor does.
  void resize(unsigned size_x_cells, unsigned size_y_cells, unsigned size_z_cells);
  // Every voxel unknown again, levels above size_z too (nav2: reset).
  void reset();

  unsigned size_x_cells() const { return size_x_; }
  unsigned size_y_cells() const { return size_y_; }
  unsigned size_z_cells() const { return size_z_; }
  // The columns, row by row (index y * size_x + x); nav2: getData (VoxelLayer copies windows of it).
  const std::vector<std::uint32_t>& columns() const { return columns_; }
  std::vector<std::uint32_t>& columns() { return columns_; }
  // The column of cell (x, y), which must lie in the grid.
  std::uint32_t column(unsigned x, unsigned y) const { return columns_[static_cast<std::size_t>(y) * size_x_ + x]; }

  // Marks voxel (x, y, z); nothing outside the grid (nav2: markVoxel).
  void mark_voxel(unsigned x, unsigned y, unsigned z);
  // Marks voxel (x, y, z) and says whether its column now holds more than mark_threshold marked voxels; false and
  // nothing outside the grid (nav2: markVoxelInMap; it sets no 2D cost, VoxelLayer writes LETHAL on true).
  bool mark_voxel_in_map(unsigned x, unsigned y, unsigned z, unsigned mark_threshold);
  // Frees voxel (x, y, z); nothing outside the grid (nav2: clearVoxel).
  void clear_voxel(unsigned x, unsigned y, unsigned z);
  // Frees voxel (x, y, z) and sets map_2d's cell (size_x * size_y cells) to 0 when the column then holds at most
  // one unknown and at most one marked voxel, thresholds nav2 fixes at 1 (nav2: clearVoxelInMap; it writes to the
  // map its last clearVoxelLineInMap was given). Nothing outside the grid. Throws std::invalid_argument when
  // map_2d's size is not the grid's.
  void clear_voxel_in_map(unsigned x, unsigned y, unsigned z, std::vector<std::uint8_t>& map_2d);
  // Every level of the column at index (y * size_x + x) free, levels above size_z too (nav2: clearVoxelColumn,
  // which only asserts the index). Throws std::out_of_range when index is past the grid.
  void clear_voxel_column(std::size_t index);

  // The state of voxel (x, y, z); kUnknown outside the grid (nav2: getVoxel).
  VoxelStatus voxel(unsigned x, unsigned y, unsigned z) const;
  // The column at (x, y): kMarked when it holds more than marked_threshold marked voxels, else kUnknown when it
  // holds more than unknown_threshold unknown ones, else kFree; kUnknown outside the grid (nav2: getVoxelColumn).
  VoxelStatus voxel_column(unsigned x, unsigned y, unsigned unknown_threshold = 0, unsigned marked_threshold = 0) const;

  // Marks every voxel the 3D walk from (x0, y0, z0) to (x1, y1, z1) visits (cell coordinates), at most
  // max_length_cells steps (nav2: markVoxelLine). Returns false, marking nothing, when an endpoint lies outside the
  // grid (see raytrace_line).
  bool mark_voxel_line(double x0, double y0, double z0, double x1, double y1, double z1,
                       unsigned max_length_cells = kNoMaxLength);
  // Frees every voxel the walk visits, starting min_length_cells along the line (nav2: clearVoxelLine). Returns
  // false, clearing nothing, when an endpoint lies outside the grid.
  bool clear_voxel_line(double x0, double y0, double z0, double x1, double y1, double z1,
                        unsigned max_length_cells = kNoMaxLength, unsigned min_length_cells = 0);
  // Frees every voxel the walk visits and, after each, sets the column's map_2d cell: when the column holds at most
  // mark_threshold marked voxels, free_cost if it holds at most unknown_threshold unknown ones, else unknown_cost;
  // a column with more marked voxels keeps its cell (nav2: clearVoxelLineInMap, VoxelLayer's raytraceFreespace
  // passes FREE_SPACE 0 and NO_INFORMATION 255). map_2d may be null: then only the voxels, as clear_voxel_line.
  // Returns false, changing nothing, when an endpoint lies outside the grid. Throws std::invalid_argument when
  // map_2d's size is not the grid's.
  bool clear_voxel_line_in_map(double x0, double y0, double z0, double x1, double y1, double z1,
                               std::vector<std::uint8_t>* map_2d, unsigned unknown_threshold, unsigned mark_threshold,
                               std::uint8_t free_cost = 0, std::uint8_t unknown_cost = 255,
                               unsigned max_length_cells = kNoMaxLength, unsigned min_length_cells = 0);

  // nav2's raytraceLine: calls visit(column_index, z_mask) for each voxel of the 3D walk from (x0, y0, z0) to
  // (x1, y1, z1), in order, where z_mask = 0x00010001 << z (the level's two bits). The walk starts min_length_cells
  // along the line (nothing when the line, truncated to whole cells, is shorter), steps along the axis with the
  // most whole cells to cross (x before y before z on ties) and takes int(min(1, max_length_cells / length) *
  // that count) steps, the length being the whole line's. Unlike nav2's raytraceLine, which trusts its callers, the
  // endpoints are checked as nav2's *Line functions check them (a coordinate >= the size: outside), and also below: a
  // coordinate <= -1 or NaN is outside (nav2 would index outside its array); one in (-1, 0) counts as 0, as in
  // nav2. Returns false, visiting nothing, when an endpoint is outside.
  template <class Visit>
  bool raytrace_line(Visit&& visit, double x0, double y0, double z0, double x1, double y1, double z1,
                     unsigned max_length_cells = kNoMaxLength, unsigned min_length_cells = 0) const;

 private:
  bool inside(double x, double y, double z) const;

  unsigned size_x_ = 0, size_y_ = 0, size_z_ = 0;
  std::vector<std::uint32_t> columns_;
};

template <class Visit>
bool VoxelGrid::raytrace_line(Visit&& visit, double x0, double y0, double z0, double x1, double y1, double z1,
                              unsigned max_length_cells, unsigned min_length_cells) const {
  if (!inside(x0, y0, z0) || !inside(x1, y1, z1)) return false;
  // The length in cells, and the start moved min_length_cells along the line (the same expressions as nav2's, so
  // the same doubles).
  const double length = std::sqrt((x0 - x1) * (x0 - x1) + (y0 - y1) * (y0 - y1) + (z0 - z1) * (z0 - z1));
  if (static_cast<unsigned>(length) < min_length_cells) return true;
  double scale = 1.0, start[3] = {x0, y0, z0};
  const double end[3] = {x1, y1, z1};
  if (length > 0.0) {
    scale = std::min(1.0, max_length_cells / length);
    for (int a = 0; a < 3; ++a) start[a] = start[a] + (end[a] - start[a]) / length * min_length_cells;
  }
  // Rounding can put the moved start a hair past the far side of the grid; nav2 would then index outside.
  if (!inside(start[0], start[1], start[2])) return false;

  // Whole cells to cross per axis (truncation towards zero, as nav2's int()).
  int steps[3];
  for (int a = 0; a < 3; ++a) steps[a] = static_cast<int>(end[a]) - static_cast<int>(start[a]);
  unsigned count[3];
  for (int a = 0; a < 3; ++a) count[a] = static_cast<unsigned>(std::abs(steps[a]));
  const int dominant = count[0] >= std::max(count[1], count[2]) ? 0 : count[1] >= count[2] ? 1 : 2;

  // The walk keeps nav2's state: a column index and the level's two-bit mask; a step in x moves the index by
  // +-1, in y by +-size_x, in z shifts the mask. Start: the cell the (moved) start lies in.
  std::ptrdiff_t index = static_cast<std::ptrdiff_t>(static_cast<unsigned>(start[1])) * size_x_ +
                         static_cast<std::ptrdiff_t>(static_cast<unsigned>(start[0]));
  std::uint32_t z_mask = 0x00010001u << static_cast<unsigned>(start[2]);
  const auto step = [&](int a) {
    if (a == 2) z_mask = steps[2] > 0 ? z_mask << 1 : z_mask >> 1;
    else index += (steps[a] > 0 ? 1 : -1) * (a == 0 ? std::ptrdiff_t{1} : std::ptrdiff_t{size_x_});
  };

  // Integer Bresenham on the dominant axis: each other axis has its own error, starting at half the dominant
  // count, growing by its own count each step, and stepping (then losing the dominant count) once it reaches it.
  const unsigned dominant_count = count[dominant];
  int error[3] = {static_cast<int>(dominant_count / 2), static_cast<int>(dominant_count / 2),
                  static_cast<int>(dominant_count / 2)};
  const unsigned clipped = static_cast<unsigned>(scale * dominant_count);
  const unsigned n_steps = std::min(clipped, dominant_count);
  for (unsigned i = 0; i < n_steps; ++i) {
    visit(static_cast<std::size_t>(index), z_mask);
    step(dominant);
    for (int a = 0; a < 3; ++a) {
      if (a == dominant) continue;
      error[a] += static_cast<int>(count[a]);
      if (static_cast<unsigned>(error[a]) >= dominant_count) {
        step(a);
        error[a] -= static_cast<int>(dominant_count);
      }
    }
  }
  visit(static_cast<std::size_t>(index), z_mask);
  return true;
}

}  // namespace stvl::layer::nav2

#include "layer/nav2_voxel_grid.hpp"

#include <stdexcept>
#include <string>

namespace stvl::layer::nav2 {
namespace {

// The two bits of level z: unknown-or-marked (z) and marked (z + 16).
std::uint32_t level_mask(unsigned z) { return 0x00010001u << z; }

// A column's marked levels (its high half) and unknown ones (high XOR low: 01, or 10 which no operation here makes).
std::uint32_t marked_bits(std::uint32_t column) { return column >> 16; }
std::uint32_t unknown_bits(std::uint32_t column) { return (column >> 16) ^ (column & 0xffffu); }

void check_size_z(unsigned size_z_cells) {
  if (size_z_cells > kMaxZCells)
    throw std::invalid_argument("z_voxels = " + std::to_string(size_z_cells) +
                                ": nav2's voxel grid holds at most 16 levels (32-bit columns)");
}

}  // namespace

unsigned num_bits(std::uint32_t n) {
  unsigned count = 0;
  for (; n != 0; n &= n - 1) ++count;  // each round drops the lowest set bit
  return count;
}

bool bits_at_most(std::uint32_t n, unsigned threshold) { return num_bits(n) <= threshold; }

VoxelGrid::VoxelGrid(unsigned size_x_cells, unsigned size_y_cells, unsigned size_z_cells) {
  resize(size_x_cells, size_y_cells, size_z_cells);
}

void VoxelGrid::resize(unsigned size_x_cells, unsigned size_y_cells, unsigned size_z_cells) {
  check_size_z(size_z_cells);
  size_x_ = size_x_cells;
  size_y_ = size_y_cells;
  size_z_ = size_z_cells;
  columns_.assign(static_cast<std::size_t>(size_x_) * size_y_, kUnknownColumn);
}

void VoxelGrid::reset() { std::fill(columns_.begin(), columns_.end(), kUnknownColumn); }

void VoxelGrid::mark_voxel(unsigned x, unsigned y, unsigned z) {
  if (x >= size_x_ || y >= size_y_ || z >= size_z_) return;
  columns_[static_cast<std::size_t>(y) * size_x_ + x] |= level_mask(z);
}

bool VoxelGrid::mark_voxel_in_map(unsigned x, unsigned y, unsigned z, unsigned mark_threshold) {
  if (x >= size_x_ || y >= size_y_ || z >= size_z_) return false;
  std::uint32_t& column = columns_[static_cast<std::size_t>(y) * size_x_ + x];
  column |= level_mask(z);
  return !bits_at_most(marked_bits(column), mark_threshold);
}

void VoxelGrid::clear_voxel(unsigned x, unsigned y, unsigned z) {
  if (x >= size_x_ || y >= size_y_ || z >= size_z_) return;
  columns_[static_cast<std::size_t>(y) * size_x_ + x] &= ~level_mask(z);
}

void VoxelGrid::clear_voxel_in_map(unsigned x, unsigned y, unsigned z, std::vector<std::uint8_t>& map_2d) {
  if (map_2d.size() != columns_.size())
    throw std::invalid_argument("clear_voxel_in_map: the 2D map has " + std::to_string(map_2d.size()) +
                                " cells, the grid " + std::to_string(columns_.size()));
  if (x >= size_x_ || y >= size_y_ || z >= size_z_) return;
  const std::size_t index = static_cast<std::size_t>(y) * size_x_ + x;
  columns_[index] &= ~level_mask(z);
  if (bits_at_most(unknown_bits(columns_[index]), 1) && bits_at_most(marked_bits(columns_[index]), 1))
    map_2d[index] = 0;
}

void VoxelGrid::clear_voxel_column(std::size_t index) {
  if (index >= columns_.size())
    throw std::out_of_range("clear_voxel_column: index " + std::to_string(index) + " past the grid's " +
                            std::to_string(columns_.size()) + " columns");
  columns_[index] = 0;
}

VoxelStatus VoxelGrid::voxel(unsigned x, unsigned y, unsigned z) const {
  if (x >= size_x_ || y >= size_y_ || z >= size_z_) return VoxelStatus::kUnknown;
  // Bits of the level set: 2 marked, 1 unknown, 0 free.
  switch (num_bits(column(x, y) & level_mask(z))) {
    case 0: return VoxelStatus::kFree;
    case 1: return VoxelStatus::kUnknown;
    default: return VoxelStatus::kMarked;
  }
}

VoxelStatus VoxelGrid::voxel_column(unsigned x, unsigned y, unsigned unknown_threshold,
                                    unsigned marked_threshold) const {
  if (x >= size_x_ || y >= size_y_) return VoxelStatus::kUnknown;
  const std::uint32_t c = column(x, y);
  if (!bits_at_most(marked_bits(c), marked_threshold)) return VoxelStatus::kMarked;
  if (!bits_at_most(unknown_bits(c), unknown_threshold)) return VoxelStatus::kUnknown;
  return VoxelStatus::kFree;
}

bool VoxelGrid::mark_voxel_line(double x0, double y0, double z0, double x1, double y1, double z1,
                                unsigned max_length_cells) {
  std::uint32_t* data = columns_.data();
  return raytrace_line([data](std::size_t index, std::uint32_t z_mask) { data[index] |= z_mask; }, x0, y0, z0, x1, y1,
                       z1, max_length_cells);
}

bool VoxelGrid::clear_voxel_line(double x0, double y0, double z0, double x1, double y1, double z1,
                                 unsigned max_length_cells, unsigned min_length_cells) {
  std::uint32_t* data = columns_.data();
  return raytrace_line([data](std::size_t index, std::uint32_t z_mask) { data[index] &= ~z_mask; }, x0, y0, z0, x1, y1,
                       z1, max_length_cells, min_length_cells);
}

bool VoxelGrid::clear_voxel_line_in_map(double x0, double y0, double z0, double x1, double y1, double z1,
                                        std::vector<std::uint8_t>* map_2d, unsigned unknown_threshold,
                                        unsigned mark_threshold, std::uint8_t free_cost, std::uint8_t unknown_cost,
                                        unsigned max_length_cells, unsigned min_length_cells) {
  if (map_2d == nullptr) return clear_voxel_line(x0, y0, z0, x1, y1, z1, max_length_cells, min_length_cells);
  if (map_2d->size() != columns_.size())
    throw std::invalid_argument("clear_voxel_line_in_map: the 2D map has " + std::to_string(map_2d->size()) +
                                " cells, the grid " + std::to_string(columns_.size()));
  std::uint32_t* data = columns_.data();
  std::uint8_t* cost = map_2d->data();
  const auto clear = [&](std::size_t index, std::uint32_t z_mask) {
    data[index] &= ~z_mask;
    // A column with more marked voxels than mark_threshold keeps its cost (VoxelLayer: LETHAL).
    if (!bits_at_most(marked_bits(data[index]), mark_threshold)) return;
    cost[index] = bits_at_most(unknown_bits(data[index]), unknown_threshold) ? free_cost : unknown_cost;
  };
  return raytrace_line(clear, x0, y0, z0, x1, y1, z1, max_length_cells, min_length_cells);
}

bool VoxelGrid::inside(double x, double y, double z) const {
  // nav2 rejects a coordinate >= the size; below, int() and unsigned() of a value in (-1, 0) are both 0.
  return x > -1.0 && y > -1.0 && z > -1.0 && x < size_x_ && y < size_y_ && z < size_z_;
}

}  // namespace stvl::layer::nav2

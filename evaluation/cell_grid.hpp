#pragma once
// A set of 2D cells (CellKey) with a count each, over a box of keys: the costmap comparison's lethal, footprint,
// observed and column sets. The box is cut into 64 x 64 tiles, each stored densely once a cell of it is added:
// membership is an index, not a hash, and memory follows the tiles in use, not the box (a footprint over a
// large world). Iteration runs tile by tile (rows of tiles, then the tile's rows), one fixed order. Two bytes a
// cell: counts stay within [0, 65535] (a column's voxels in the band are far fewer).
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/voxel_key.hpp"

namespace stvl::evaluation {

class CellGrid {
 public:
  CellGrid() = default;  // no box: holds nothing, inserts throw
  // Every cell of [lo, hi] (inclusive) absent. Throws std::invalid_argument beyond 2.5e7 tiles (1e11 cells).
  CellGrid(const CellKey& lo, const CellKey& hi);
  // The smallest box holding these cells: empty (covering), or with them (of).
  static CellGrid covering(const std::vector<CellKey>& cells);
  static CellGrid of(const std::vector<CellKey>& cells);
  static CellGrid of(const CellSet& cells);

  // Whether c is present, and its count (0 when absent or outside the box).
  bool contains(const CellKey& c) const { return count(c) > 0; }
  int count(const CellKey& c) const {
    if (!covers(c)) return 0;
    const std::int32_t tile = tile_of_[tile_index(c)];
    return tile < 0 ? 0 : tiles_[static_cast<std::size_t>(tile)][offset(c)];
  }
  bool covers(const CellKey& c) const {  // inside the box
    return c.x >= lo_.x && c.y >= lo_.y && std::int64_t{c.x} - lo_.x < width_ && std::int64_t{c.y} - lo_.y < height_;
  }
  // True when a cell within Chebyshev distance tol of c is present (c itself first: the usual hit).
  bool near(const CellKey& c, int tol) const;
  // Adds n to c's count, kept within [0, 65535] (c is in the set while its count is positive). Throws
  // std::out_of_range outside the box.
  void add(const CellKey& c, int n = 1);
  // Adds c with count 1 when absent (a present cell keeps its count). Throws std::out_of_range outside the box.
  void insert(const CellKey& c) {
    if (!contains(c)) add(c, 1);
  }
  std::size_t size() const { return size_; }  // cells with a positive count
  bool empty() const { return size_ == 0; }   // no cell present
  // The box's corners, inclusive (hi < lo: no box).
  CellKey lo() const { return lo_; }
  CellKey hi() const {
    return {static_cast<std::int32_t>(lo_.x + width_ - 1), static_cast<std::int32_t>(lo_.y + height_ - 1)};
  }

  // f(cell, count) for each present cell, tile by tile.
  template <class F>
  void for_each(F&& f) const {
    for (std::int64_t ty = 0; ty < tiles_y_; ++ty)
      for (std::int64_t tx = 0; tx < tiles_x_; ++tx) {
        const std::int32_t tile = tile_of_[static_cast<std::size_t>(ty * tiles_x_ + tx)];
        if (tile < 0) continue;
        const Tile& counts = tiles_[static_cast<std::size_t>(tile)];
        for (int i = 0; i < kTile * kTile; ++i)
          if (counts[static_cast<std::size_t>(i)] > 0)
            f(CellKey{static_cast<std::int32_t>(lo_.x + tx * kTile + (i & (kTile - 1))),
                      static_cast<std::int32_t>(lo_.y + ty * kTile + (i >> kTileBits))},
              int{counts[static_cast<std::size_t>(i)]});
      }
  }
  std::vector<CellKey> cells() const;  // present cells, tile by tile
  CellSet to_set() const;              // the present cells as a CellSet

 private:
  static constexpr int kTileBits = 6, kTile = 1 << kTileBits;
  using Tile = std::array<std::uint16_t, kTile * kTile>;
  std::size_t tile_index(const CellKey& c) const {
    return static_cast<std::size_t>(((std::int64_t{c.y} - lo_.y) >> kTileBits) * tiles_x_ +
                                    ((std::int64_t{c.x} - lo_.x) >> kTileBits));
  }
  static std::size_t offset(std::int64_t dx, std::int64_t dy) {
    return static_cast<std::size_t>(((dy & (kTile - 1)) << kTileBits) | (dx & (kTile - 1)));
  }
  std::size_t offset(const CellKey& c) const { return offset(std::int64_t{c.x} - lo_.x, std::int64_t{c.y} - lo_.y); }

  CellKey lo_{0, 0};
  std::int64_t width_ = 0, height_ = 0, tiles_x_ = 0, tiles_y_ = 0;
  std::vector<std::int32_t> tile_of_;  // per tile of the box, row by row: its index in tiles_, -1 while empty
  std::vector<Tile> tiles_;
  std::size_t size_ = 0;
};

}  // namespace stvl::evaluation

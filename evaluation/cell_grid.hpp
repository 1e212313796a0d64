#pragma once
// A set of 2D cells (CellKey) with a count each, stored densely over a box of keys: the costmap comparison's
// lethal, footprint, observed and column sets. Membership is an index, not a hash; iteration runs row by row
// (y, then x), so every result built from it is in one fixed order. Two bytes a cell: counts stay within
// [0, 65535] (a column's voxels in the band are far fewer).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/voxel_key.hpp"

namespace stvl::evaluation {

class CellGrid {
 public:
  CellGrid() = default;  // no box: holds nothing, inserts throw
  // Every cell of [lo, hi] (inclusive) absent. Throws std::invalid_argument beyond 4e8 cells (800 MB).
  CellGrid(const CellKey& lo, const CellKey& hi);
  // The smallest box holding these cells: empty (covering), or with them (of).
  static CellGrid covering(const std::vector<CellKey>& cells);
  static CellGrid of(const std::vector<CellKey>& cells);
  static CellGrid of(const CellSet& cells);

  bool contains(const CellKey& c) const { return count(c) > 0; }
  int count(const CellKey& c) const { return covers(c) ? counts_[index(c)] : 0; }
  bool covers(const CellKey& c) const {  // inside the box
    return c.x >= lo_.x && c.y >= lo_.y && std::int64_t{c.x} - lo_.x < width_ && std::int64_t{c.y} - lo_.y < height_;
  }
  // True when a cell within Chebyshev distance tol of c is present (c itself first: the usual hit).
  bool near(const CellKey& c, int tol) const;
  // Adds n to c's count, kept within [0, 65535] (c is in the set while its count is positive). Throws
  // std::out_of_range outside the box.
  void add(const CellKey& c, int n = 1);
  void insert(const CellKey& c) {
    if (!contains(c)) add(c, 1);
  }
  std::size_t size() const { return size_; }  // cells with a positive count
  CellKey lo() const { return lo_; }  // the box (hi < lo: no box)
  CellKey hi() const { return {lo_.x + width_ - 1, lo_.y + height_ - 1}; }
  bool empty() const { return size_ == 0; }

  // f(cell, count) for each present cell, row by row.
  template <class F>
  void for_each(F&& f) const {
    for (int y = 0; y < height_; ++y)
      for (int x = 0; x < width_; ++x)
        if (const int n = counts_[static_cast<std::size_t>(y) * width_ + x]; n > 0) f(CellKey{lo_.x + x, lo_.y + y}, n);
  }
  std::vector<CellKey> cells() const;  // present cells, row by row
  CellSet to_set() const;

 private:
  std::size_t index(const CellKey& c) const {
    return static_cast<std::size_t>(c.y - lo_.y) * width_ + static_cast<std::size_t>(c.x - lo_.x);
  }

  CellKey lo_{0, 0};
  int width_ = 0, height_ = 0;
  std::vector<std::uint16_t> counts_;
  std::size_t size_ = 0;
};

}  // namespace stvl::evaluation

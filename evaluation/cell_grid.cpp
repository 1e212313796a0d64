#include "evaluation/cell_grid.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace stvl::evaluation {

CellGrid::CellGrid(const CellKey& lo, const CellKey& hi) : lo_(lo) {
  const std::int64_t width = std::int64_t{hi.x} - lo.x + 1, height = std::int64_t{hi.y} - lo.y + 1;
  if (width < 1 || height < 1) return;  // an empty box
  const std::int64_t tiles_x = (width + kTile - 1) / kTile, tiles_y = (height + kTile - 1) / kTile;
  if (tiles_x * tiles_y > 25'000'000)
    throw std::invalid_argument("cell grid of " + std::to_string(width) + " x " + std::to_string(height) +
                                " cells is too large");
  width_ = width, height_ = height, tiles_x_ = tiles_x, tiles_y_ = tiles_y;
  tile_of_.assign(static_cast<std::size_t>(tiles_x * tiles_y), -1);
}

CellGrid CellGrid::covering(const std::vector<CellKey>& cells) {
  if (cells.empty()) return {};
  CellKey lo = cells.front(), hi = cells.front();
  for (const CellKey& c : cells) {
    lo = {std::min(lo.x, c.x), std::min(lo.y, c.y)};
    hi = {std::max(hi.x, c.x), std::max(hi.y, c.y)};
  }
  return CellGrid(lo, hi);
}

CellGrid CellGrid::of(const std::vector<CellKey>& cells) {
  CellGrid grid = covering(cells);
  for (const CellKey& c : cells) grid.insert(c);
  return grid;
}

CellGrid CellGrid::of(const CellSet& cells) { return of(std::vector<CellKey>(cells.begin(), cells.end())); }

bool CellGrid::near(const CellKey& c, int tol) const {
  if (contains(c)) return true;
  // Only the part of the (2 tol + 1)^2 square inside the box can hold a cell.
  const std::int64_t x0 = std::max<std::int64_t>(std::int64_t{c.x} - tol, lo_.x),
                     x1 = std::min<std::int64_t>(std::int64_t{c.x} + tol, lo_.x + width_ - 1),
                     y0 = std::max<std::int64_t>(std::int64_t{c.y} - tol, lo_.y),
                     y1 = std::min<std::int64_t>(std::int64_t{c.y} + tol, lo_.y + height_ - 1);
  for (std::int64_t y = y0; y <= y1; ++y)
    for (std::int64_t x = x0; x <= x1; ++x)
      if (contains({static_cast<std::int32_t>(x), static_cast<std::int32_t>(y)})) return true;
  return false;
}

void CellGrid::add(const CellKey& c, int n) {
  if (!covers(c))
    throw std::out_of_range("cell (" + std::to_string(c.x) + ", " + std::to_string(c.y) + ") outside the grid");
  std::int32_t& tile = tile_of_[tile_index(c)];
  if (tile < 0) {
    if (n <= 0) return;  // an absent cell stays absent
    tile = static_cast<std::int32_t>(tiles_.size());
    tiles_.emplace_back().fill(0);
  }
  std::uint16_t& count = tiles_[static_cast<std::size_t>(tile)][offset(c)];
  const bool was = count > 0;
  count = static_cast<std::uint16_t>(std::clamp<std::int64_t>(std::int64_t{count} + n, 0, 65535));
  if (count > 0 && !was) ++size_;
  if (count == 0 && was) --size_;
}

std::vector<CellKey> CellGrid::cells() const {
  std::vector<CellKey> out;
  out.reserve(size_);
  for_each([&](const CellKey& c, int) { out.push_back(c); });
  return out;
}

CellSet CellGrid::to_set() const {
  CellSet out;
  for_each([&](const CellKey& c, int) { out.insert(c); });
  return out;
}

}  // namespace stvl::evaluation

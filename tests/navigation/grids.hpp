#pragma once
// The navigation tests' hand-made grids: a costmap of width x height cells filled with one cost, and a cell of it.
#include <cstdint>

#include "mapping/costmap.hpp"

namespace stvl::navigation::test {

inline mapping::Costmap2D grid(int width, int height, double resolution_m, std::uint8_t fill = mapping::kCostFree) {
  mapping::Costmap2D g;
  g.width = width;
  g.height = height;
  g.resolution_m = resolution_m;
  g.cells.assign(static_cast<std::size_t>(width) * height, fill);
  return g;
}

inline std::uint8_t& cell(mapping::Costmap2D& g, int x, int y) {
  return g.cells[static_cast<std::size_t>(y) * g.width + x];
}

}  // namespace stvl::navigation::test

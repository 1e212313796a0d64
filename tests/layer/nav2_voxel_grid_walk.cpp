// Prints the voxels layer/nav2_voxel_grid.hpp's walk (nav2's raytraceLine) visits, for nav2_voxel_grid_check.py.
// Each stdin line: size_x size_y size_z x0 y0 z0 x1 y1 z1 max_length min_length (cells). Each stdout line: the
// voxels as "x,y,z" separated by spaces, or "outside" when the walk refused an endpoint.
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "layer/nav2_voxel_grid.hpp"

int main() {
  unsigned sx = 0, sy = 0, sz = 0, max_length = 0, min_length = 0;
  double x0 = 0, y0 = 0, z0 = 0, x1 = 0, y1 = 0, z1 = 0;
  while (std::cin >> sx >> sy >> sz >> x0 >> y0 >> z0 >> x1 >> y1 >> z1 >> max_length >> min_length) {
    const stvl::layer::nav2::VoxelGrid grid(sx, sy, sz);
    std::string line;
    const auto print = [&](std::size_t index, std::uint32_t z_mask) {
      unsigned z = 0;
      while (z < 32 && ((z_mask >> z) & 1u) == 0) ++z;  // the level's low bit
      if (!line.empty()) line += ' ';
      line += std::to_string(index % sx) + ',' + std::to_string(index / sx) + ',' + std::to_string(z);
    };
    if (!grid.raytrace_line(print, x0, y0, z0, x1, y1, z1, max_length, min_length)) line = "outside";
    std::cout << line << '\n';
  }
  return 0;
}

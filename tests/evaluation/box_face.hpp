#pragma once
// The tiny world's box seen face-on (tests/evaluation): a box at x 2.05..2.65 m, |y| <= 0.25 m, z 0.15..0.65 m,
// whose front face at 0.1 m voxels is the layer x = 20 (y keys -3..2, z keys 1..6); maps holding chosen voxels.
#include <vector>

#include "common/voxel_key.hpp"
#include "mapping/voxel_map.hpp"

namespace stvl::evaluation::test {

inline std::vector<VoxelKey> box_face_voxels() {
  std::vector<VoxelKey> keys;
  for (int y = -3; y <= 2; ++y)
    for (int z = 1; z <= 6; ++z) keys.push_back({20, y, z});
  return keys;
}

// A 0.1 m map holding `keys`, each last marked at time_s.
inline mapping::VoxelMap map_with(const std::vector<VoxelKey>& keys, double time_s) {
  mapping::StvlConfig c;
  c.voxel_size_m = 0.1;
  mapping::VoxelMap map(c);
  std::vector<mapping::Voxel> voxels;
  for (const auto& k : keys) voxels.push_back({k, time_s});
  map.set_voxels(voxels);
  return map;
}

}  // namespace stvl::evaluation::test

#pragma once
// What tests/evaluation builds on the fixture's box worlds (stvl::test::kBoxWorld, kBoxAndCartWorld in
// tests/support/fixture.hpp: a box at x 2.05..2.65 m, |y| <= 0.25 m, z 0.15..0.65 m, and a mocap cart the tests
// move): the box's front face at 0.1 m voxels (the layer x = 20, y keys -3..2, z keys 1..6), the evaluation
// config at 0.1 m, maps holding chosen voxels.
#include <vector>

#include "common/voxel_key.hpp"
#include "evaluation/config.hpp"
#include "mapping/voxel_map.hpp"

namespace stvl::evaluation::test {

// 0.1 m voxels, the band 0..2 m, matches within tol voxels.
inline EvaluationConfig config_at_0p1(int tol) {
  EvaluationConfig c;
  c.voxel_size_m = 0.1;
  c.min_obstacle_height_m = 0.0;
  c.max_obstacle_height_m = 2.0;
  c.tolerance_voxels = tol;
  return c;
}

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

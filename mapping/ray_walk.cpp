#include "mapping/ray_walk.hpp"

namespace stvl::mapping {

std::vector<VoxelKey> ray_voxels(const Eigen::Vector3d& s_vox, const Eigen::Vector3d& e_vox) {
  std::vector<VoxelKey> keys;
  const int present = 1;
  walk_ray_blocks(
      s_vox, e_vox, [&](const VoxelKey&) { return &present; },
      [&](const int*, const VoxelKey& key) { keys.push_back(key); });
  return keys;
}

}  // namespace stvl::mapping

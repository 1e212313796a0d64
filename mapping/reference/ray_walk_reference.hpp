#pragma once
// Plain twin of mapping/ray_walk.hpp: the 3D DDA of Amanatides & Woo (1987) voxel by voxel, no blocks, no jumps,
// for tests only (library stvl_mapping_reference, linked by no module). Same contract as ray_walk.hpp.
#include <Eigen/Core>

#include <vector>

#include "common/voxel_key.hpp"

namespace stvl::mapping::reference {

// The voxels of the segment s_vox -> e_vox (voxel units), in order, per the contract in mapping/ray_walk.hpp.
std::vector<VoxelKey> ray_voxels(const Eigen::Vector3d& s_vox, const Eigen::Vector3d& e_vox);

}  // namespace stvl::mapping::reference

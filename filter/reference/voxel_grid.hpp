#pragma once
// Plain voxel grid, written from the comment in filter/voxel_grid.hpp alone (a std::map over voxel indices),
// as the reference the optimized CPU and CUDA voxel grids must match bit for bit. Tests only: it is in the
// stvl_filter_reference library, not in stvl_filter.
#include <Eigen/Core>

#include "filter/voxel_grid.hpp"

namespace stvl::filter::reference {

// Same contract as filter::voxel_grid for a valid config and a cloud whose box fits 64-bit keys (neither is
// checked here).
Eigen::Matrix3Xf voxel_grid(const Eigen::Matrix3Xf& points, const VoxelGridConfig& config);

}  // namespace stvl::filter::reference

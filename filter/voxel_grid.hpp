#pragma once
#include <Eigen/Core>

namespace stvl::filter {

// PCL VoxelGrid semantics: one output point per occupied voxel, the centroid of its points (per axis
// float(sum / count), the sum in double in point-index order); voxels with fewer than min_points_per_voxel
// points dropped; NaN/Inf skipped. The plain reference is filter/reference/voxel_grid.cpp.
// Voxel of a point: floor(double(x) / voxel_size_m) per axis. Output sorted by voxel key
// (x fastest, then y, then z). Keys are 64-bit over the cloud's bounding box: a cloud whose box needs more
// than 2^64 voxels throws std::invalid_argument saying so; so does a voxel size that is not finite and > 0.
struct VoxelGridConfig {
  double voxel_size_m = 0.05;
  int min_points_per_voxel = 1;  // 0 behaves as 1
};

// threads: 0 = std::thread::hardware_concurrency().
Eigen::Matrix3Xf voxel_grid(const Eigen::Matrix3Xf& points, const VoxelGridConfig& config, int threads = 0);

}  // namespace stvl::filter

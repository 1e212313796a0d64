#pragma once
#include <Eigen/Core>

#include <cstdint>

namespace stvl::filter {

// CSNB decimation (after Bedkowski 2013, "Cubic Subspaces - Neighboring Buckets"). Space from the cloud's
// bounding-box minimum is split into 2^n cubes per axis, n = 4..9: with grid_exponent 0 the cube edge is
// voxel_size_m (or extent / 2^9 when larger), with a given n it is extent / 2^n; neighbours are points
// closer than voxel_size_m (strict), searched in the cubes within ceil(voxel_size_m / edge) of the point's
// cube (27 cubes whenever edge >= voxel_size_m). A live point is marked when it has more than
// max_neighbours live neighbours; while more than batch_size points are marked, batch_size of them chosen at
// random are deleted and counts updated; then the rest are deleted. One point per occupied cube (the one
// nearest the cube centre) is an anchor and is never deleted, so no occupied cube is lost.
// Guarantee: every kept non-anchor has at most max_neighbours kept neighbours; an anchor that still has
// more after the loop has its non-anchor neighbours deleted, so an anchor exceeds max_neighbours only
// through other anchors (at most 26 when edge >= voxel_size_m). Output sorted by (cube, point index);
// NaN/Inf points are dropped; same output on CPU and CUDA for the same seed.
struct CsnbConfig {
  double voxel_size_m = 0.05;    // distance threshold; the cube edge is at least this
  int max_neighbours = 4;        // count threshold
  int batch_size = 1000;         // K
  int grid_exponent = 0;         // n: 0 = auto (edge = voxel_size_m, n from the extent), else 4..9
  std::uint64_t seed = 1;
};

Eigen::Matrix3Xf csnb(const Eigen::Matrix3Xf& points, const CsnbConfig& config, int threads = 0);

}  // namespace stvl::filter

#pragma once
#include <Eigen/Core>

#include <cstdint>

namespace stvl::filter {

// CSNB decimation (after Bedkowski 2013, "Cubic Subspaces - Neighboring Buckets"), defined exactly below: the
// plain reference (filter/reference/csnb.cpp) is written from this comment alone. d = voxel_size_m.
// Grid: over the finite points (NaN/Inf are dropped), min[a] is the smallest float coordinate on axis a and
// extent the largest side, double(max[a]) - double(min[a]). With grid_exponent 0 the cube edge is
// max(d, extent / 512) and n = ceil(log2(max(extent / edge, 1))) (std::log2, double) clamped to 4..9; with a
// given n it is extent / 2^n (d when extent is 0). reach = ceil(d / edge) clamped to 1..2^n - 1. A point's
// cube: c[a] = floor((double(v[a]) - min[a]) / edge) clamped to 0..2^n - 1; cubes are ordered by
// (c[2], c[1], c[0]), points by (cube, point index).
// Neighbours: two points whose cubes are at most reach apart on every axis and whose float squared distance
// ((dx*dx + dy*dy) + dz*dz, every step rounded to float) is below float(d * d).
// Anchors: in each occupied cube the point nearest its centre (min[a] + (c[a] + 0.5) * edge; squared
// distance in double, as above), ties to the lowest index. Anchors are never deleted, so no cube is lost.
// Random order: the non-anchor points by (h >> 32, position in the (cube, index) order), ascending, where
// h = s(s(s(seed) ^ 0x43534E42) ^ point index) and s is splitmix64 (x += 0x9E3779B97F4A7C15;
// x = (x ^ x >> 30) * 0xBF58476D1CE4E5B9; x = (x ^ x >> 27) * 0x94D049BB133111EB; x ^ x >> 31), so that the
// CPU and CUDA agree.
// Loop: a live non-anchor point is marked when it has more than max_neighbours live neighbours; while more
// than batch_size points are marked, the first batch_size marked ones in the random order are deleted and the
// counts updated; then the rest are deleted. Last, every anchor with more than max_neighbours live
// neighbours (all judged on the same live set) deletes its non-anchor neighbours.
// Guarantee: every kept non-anchor has at most max_neighbours kept neighbours; an anchor exceeds
// max_neighbours only through other anchors (at most 26 when edge >= d). Output: the kept points in (cube,
// index) order; the same on CPU and CUDA for the same seed.
struct CsnbConfig {
  double voxel_size_m = 0.05;  // distance threshold; the cube edge is at least this
  int max_neighbours = 4;      // count threshold
  int batch_size = 1000;       // K
  int grid_exponent = 0;       // n: 0 = auto (edge = voxel_size_m, n from the extent), else 4..9
  std::uint64_t seed = 1;
};

Eigen::Matrix3Xf csnb(const Eigen::Matrix3Xf& points, const CsnbConfig& config, int threads = 0);

}  // namespace stvl::filter

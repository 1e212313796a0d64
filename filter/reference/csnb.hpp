#pragma once
// The CSNB of filter/csnb.hpp, written from that header's comment alone and literally: brute-force neighbour
// lists, and per iteration a fresh count of every live point's live neighbours, the first batch_size marked
// points of the random order deleted. Slow (quadratic in the points); the reference the optimized CPU and
// CUDA code must match bit for bit. Tests only: it is in the stvl_filter_reference library, not in
// stvl_filter, and uses nothing of filter/detail.
#include <Eigen/Core>

#include <array>

#include "filter/csnb.hpp"

namespace stvl::filter::reference {

// The cube grid of csnb.hpp over a cloud's finite points.
struct CsnbGrid {
  double min_m[3] = {0, 0, 0};  // the bounding box's minimum
  double extent_m = 0.0;        // its largest side
  double cube_edge_m = 1.0;
  int grid_exponent = 4;  // n: 2^n cubes per axis
  int reach = 1;          // cubes searched on each side
  float radius_sq = 0.f;  // float(voxel_size_m^2)

  // Cube coordinates (x, y, z) of a finite point, clamped to the grid.
  std::array<int, 3> cube(float x, float y, float z) const;
  // Neighbours: cube coordinates at most `reach` apart on every axis and float squared distance < radius_sq.
  bool neighbours(const float* a, const std::array<int, 3>& cube_a, const float* b,
                  const std::array<int, 3>& cube_b) const;
};

// The grid of `points` (at least one finite) for a valid config.
CsnbGrid csnb_grid(const Eigen::Matrix3Xf& points, const CsnbConfig& config);

// Same contract as filter::csnb for a valid config.
Eigen::Matrix3Xf csnb(const Eigen::Matrix3Xf& points, const CsnbConfig& config);

}  // namespace stvl::filter::reference

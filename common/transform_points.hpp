#pragma once
// Points moved to another frame in float, rounded exactly as Eigen rounds `(R * P).colwise() + t` for a 3 x N
// float matrix P (its product kernels sum r_i0 x + (r_i1 y + r_i2 z), then add t_i), in one pass without the
// product's packing. tests/common compares the two on clouds of every size class Eigen treats apart.
#include <cstddef>

#include <Eigen/Core>

namespace stvl {

// out_j = R in_j + t for count points of 3 interleaved floats (x, y, z); in and out may not overlap.
inline void transform_points(const Eigen::Matrix3f& R, const Eigen::Vector3f& t, const float* in, float* out,
                             std::size_t count) {
  const float r00 = R(0, 0), r01 = R(0, 1), r02 = R(0, 2), r10 = R(1, 0), r11 = R(1, 1), r12 = R(1, 2), r20 = R(2, 0),
              r21 = R(2, 1), r22 = R(2, 2), t0 = t.x(), t1 = t.y(), t2 = t.z();
  const float* __restrict p = in;
  float* __restrict o = out;
  for (std::size_t j = 0; j < count; ++j) {
    const float x = p[3 * j], y = p[3 * j + 1], z = p[3 * j + 2];
    o[3 * j] = (r00 * x + (r01 * y + r02 * z)) + t0;
    o[3 * j + 1] = (r10 * x + (r11 * y + r12 * z)) + t1;
    o[3 * j + 2] = (r20 * x + (r21 * y + r22 * z)) + t2;
  }
}

}  // namespace stvl

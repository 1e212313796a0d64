#pragma once
#include <Eigen/Core>

#include <cstdint>

#include "filter/detail/common.hpp"
#include "filter/detail/shared.hpp"

namespace stvl::filter::test {

// Uniform random cloud in [lo, hi]^3 from the counter-based hash.
inline Eigen::Matrix3Xf random_cloud(std::uint64_t seed, Eigen::Index n, float lo, float hi) {
  Eigen::Matrix3Xf points(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      const double u = double(detail::hash3(seed, std::uint64_t(i), std::uint64_t(a)) >> 11) * 0x1.0p-53;
      points(a, i) = static_cast<float>(lo + (hi - lo) * u);
    }
  }
  return points;
}

// Turns the filters' AVX2 paths off for its lifetime (they are on by default wherever the CPU has AVX2).
struct WithoutSimd {
  WithoutSimd() { detail::set_simd_enabled(false); }
  ~WithoutSimd() { detail::set_simd_enabled(true); }
  WithoutSimd(const WithoutSimd&) = delete;
  WithoutSimd& operator=(const WithoutSimd&) = delete;
};

}  // namespace stvl::filter::test

#pragma once
#include <gtest/gtest.h>

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

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

// Draws from the counter-based hash: the same sequence for the same seed on every platform.
struct Random {
  std::uint64_t seed;
  std::uint64_t counter = 0;
  std::uint64_t bits() { return detail::hash3(seed, counter++, 0x52414E44ull); }
  double uniform() { return double(bits() >> 11) * 0x1.0p-53; }  // [0, 1)
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  double log_uniform(double lo, double hi) { return lo * std::pow(hi / lo, uniform()); }
  int range(int lo, int hi) { return lo + int(bits() % std::uint64_t(hi - lo + 1)); }  // [lo, hi]
  template <class T, std::size_t N>
  T pick(const T (&values)[N]) {
    return values[bits() % N];
  }
};

// A random cloud of n points in a box of side `size_m` at a random offset (negative coordinates too), of one
// of several shapes: uniform, dense blobs, a floor with a few points above, points on a lattice of step
// `lattice_m` from an origin on it (duplicates, and coordinates on voxel boundaries). A share `bad` of the
// points gets a NaN or infinite coordinate. `what`, when given, is set to a description for failure messages.
inline Eigen::Matrix3Xf mixed_cloud(Random& r, Eigen::Index n, double size_m, double lattice_m, double bad,
                                    std::string* what) {
  const double offsets[] = {0.0, -0.5, 1.0, -30.0, 250.0, -4000.0};
  double origin[3];
  for (double& o : origin) o = r.pick(offsets) * size_m + r.uniform(-1.0, 1.0) * size_m;
  const int shape = r.range(0, 3);
  if (shape == 3) {
    for (double& o : origin) o = std::round(o / lattice_m) * lattice_m;
  }
  const int blobs = r.range(1, 12);
  double centres[12][3];
  for (auto& c : centres)
    for (int a = 0; a < 3; ++a) c[a] = r.uniform(0.1, 0.9) * size_m;
  const double blob_m = size_m * r.log_uniform(0.005, 0.1);
  Eigen::Matrix3Xf points(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    double v[3];
    for (double& x : v) x = r.uniform() * size_m;
    if (shape == 1) {
      const auto& c = centres[r.bits() % std::uint64_t(blobs)];
      for (int a = 0; a < 3; ++a) v[a] = c[a] + blob_m * (r.uniform() + r.uniform() + r.uniform() - 1.5);
    } else if (shape == 2 && r.uniform() < 0.9) {
      v[2] = size_m * 0.001 * r.uniform();
    } else if (shape == 3) {
      for (double& x : v) x = std::round(x / lattice_m) * lattice_m;
    }
    for (int a = 0; a < 3; ++a) points(a, i) = static_cast<float>(origin[a] + v[a]);
    if (r.uniform() < bad) {
      const float odd[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                           -std::numeric_limits<float>::infinity()};
      points(r.range(0, 2), i) = r.pick(odd);
    }
  }
  if (what) {
    const char* shapes[] = {"uniform", "blobs", "floor", "lattice"};
    *what = std::string(shapes[shape]) + " cloud of " + std::to_string(n) + " points, side " + std::to_string(size_m) +
            " m at (" + std::to_string(origin[0]) + ", " + std::to_string(origin[1]) + ", " +
            std::to_string(origin[2]) + "), bad share " + std::to_string(bad);
  }
  return points;
}

inline bool any_finite(const Eigen::Matrix3Xf& points) {
  for (Eigen::Index i = 0; i < points.cols(); ++i)
    if (points.col(i).allFinite()) return true;
  return false;
}

// Equal bit for bit, point for point and in the same order.
inline ::testing::AssertionResult same_bits(const Eigen::Matrix3Xf& actual, const Eigen::Matrix3Xf& expected) {
  if (actual.cols() != expected.cols()) {
    return ::testing::AssertionFailure() << actual.cols() << " points, expected " << expected.cols();
  }
  for (Eigen::Index i = 0; i < actual.cols(); ++i) {
    if (std::memcmp(actual.col(i).data(), expected.col(i).data(), 3 * sizeof(float)) != 0) {
      return ::testing::AssertionFailure()
             << "point " << i << " is (" << actual(0, i) << ", " << actual(1, i) << ", " << actual(2, i)
             << "), expected (" << expected(0, i) << ", " << expected(1, i) << ", " << expected(2, i) << ")";
    }
  }
  return ::testing::AssertionSuccess();
}

// The filters' SIMD switch (detail::set_simd_enabled) on or off for its lifetime, back on after.
struct SimdSetting {
  explicit SimdSetting(bool on) { detail::set_simd_enabled(on); }
  ~SimdSetting() { detail::set_simd_enabled(true); }
  SimdSetting(const SimdSetting&) = delete;
  SimdSetting& operator=(const SimdSetting&) = delete;
};
struct WithoutSimd : SimdSetting {
  WithoutSimd() : SimdSetting(false) {}
};

}  // namespace stvl::filter::test

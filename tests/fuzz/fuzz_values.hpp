#pragma once
// Value generators shared by the fuzz targets: numbers are drawn from a table of edge cases (NaN, +-Inf,
// denormals, +-0, extremes, typical sizes), from plausible ranges, or from raw bytes, so that the fuzzer reaches
// both the validation paths and the arithmetic behind them.
#include <fuzzer/FuzzedDataProvider.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace stvl::fuzz {

template <typename T>
T edge_value(FuzzedDataProvider& in) {
  using L = std::numeric_limits<T>;
  static const T table[] = {
      T(0),        -T(0),        L::quiet_NaN(), L::infinity(),    -L::infinity(), L::denorm_min(), L::min(), L::max(),
      L::lowest(), L::epsilon(), T(1e30),        T(-1e30),         T(1e-30),       T(0.05),         T(1),     T(-1),
      T(0.01),     T(10),        T(2147483647),  T(-2147483648.0), T(9.3e18),      T(-9.3e18),      T(3.4e9), T(0.5)};
  return table[in.ConsumeIntegralInRange<std::size_t>(0, sizeof(table) / sizeof(table[0]) - 1)];
}

template <typename T>
T any_value(FuzzedDataProvider& in, T lo, T hi) {
  switch (in.ConsumeIntegralInRange<int>(0, 3)) {
    case 0: return edge_value<T>(in);
    case 1: {
      T v;
      const auto bytes = in.ConsumeBytes<std::uint8_t>(sizeof(T));
      if (bytes.size() != sizeof(T)) return T(0);
      std::memcpy(&v, bytes.data(), sizeof(T));
      return v;
    }
    default: return in.ConsumeFloatingPointInRange<T>(lo, hi);
  }
}

// A rigid pose most of the time; sometimes a raw (possibly non-orthonormal or non-finite) 3x4 matrix.
inline Eigen::Isometry3d any_pose(FuzzedDataProvider& in) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (in.ConsumeIntegralInRange<int>(0, 7) == 0) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) T.matrix()(r, c) = any_value<double>(in, -10.0, 10.0);
    return T;
  }
  Eigen::Quaterniond q(in.ConsumeFloatingPointInRange<double>(-1, 1), in.ConsumeFloatingPointInRange<double>(-1, 1),
                       in.ConsumeFloatingPointInRange<double>(-1, 1), in.ConsumeFloatingPointInRange<double>(-1, 1));
  if (q.norm() < 1e-6) q = Eigen::Quaterniond::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  for (int i = 0; i < 3; ++i) T.translation()[i] = any_value<double>(in, -50.0, 50.0);
  return T;
}

}  // namespace stvl::fuzz

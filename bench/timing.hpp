#pragma once
// Wall-clock timing for the benchmarks (the only place in the project where the wall clock is read for a result).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>
#include <vector>

namespace stvl::bench {

// Time of one call of fn(), in ms.
template <class Fn>
double time_once_ms(Fn&& fn) {
  const auto start = std::chrono::steady_clock::now();
  fn();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// Times fn() `repetitions` times (at least once) after `warmup` untimed calls; returns {mean, std} in ms.
template <class Fn>
std::pair<double, double> time_ms(Fn&& fn, int warmup, int repetitions) {
  for (int i = 0; i < warmup; ++i) fn();
  double sum = 0.0, sum_sq = 0.0;
  const int n = repetitions > 0 ? repetitions : 1;
  for (int i = 0; i < n; ++i) {
    const double ms = time_once_ms(fn);
    sum += ms;
    sum_sq += ms * ms;
  }
  const double mean = sum / n;
  return {mean, std::sqrt(std::max(0.0, sum_sq / n - mean * mean))};
}

// Median of v (the mean of the two middle values for an even count); 0 when v is empty.
inline double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace stvl::bench

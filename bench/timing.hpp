#pragma once
// Wall-clock timing for the benchmarks (the only place in the project where the wall clock is read for a result).
#include <algorithm>
#include <cmath>
#include <utility>

#include "common/stopwatch.hpp"

namespace stvl::bench {

// Time of one call of fn(), in ms.
template <class Fn>
double time_once_ms(Fn&& fn) {
  const Stopwatch watch;
  fn();
  return watch.elapsed_ms();
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

}  // namespace stvl::bench

#pragma once
#include <chrono>
#include <cmath>
#include <utility>

namespace stvl::filter {

template <class Fn>
std::pair<double, double> time_ms(Fn&& fn, int warmup, int repetitions) {
  for (int i = 0; i < warmup; ++i) fn();
  double sum = 0.0, sum_sq = 0.0;
  const int n = repetitions > 0 ? repetitions : 1;
  for (int i = 0; i < n; ++i) {
    const auto start = std::chrono::steady_clock::now();
    fn();
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    sum += ms;
    sum_sq += ms * ms;
  }
  const double mean = sum / n;
  return {mean, std::sqrt(std::max(0.0, sum_sq / n - mean * mean))};
}

}  // namespace stvl::filter

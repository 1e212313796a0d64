#pragma once
// The generator's random numbers: splitmix64 (common/splitmix.hpp) and our own mapping to ranges, so that one
// seed gives the same world with every standard library (std::uniform_*_distribution are not portable).
#include <cmath>
#include <cstdint>

#include "common/splitmix.hpp"

namespace stvl::worldgen {

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(splitmix64_mix(seed ^ 0x6F66666963650000ull)) {}  // "office"
  std::uint64_t next() { return splitmix64_mix(state_ += 0x9E3779B97F4A7C15ull); }
  // Uniform in [0, 1): the top 53 bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Uniform in lo..hi (both included).
  int integer(int lo, int hi) {
    const int n = hi - lo + 1;
    const int k = static_cast<int>(uniform() * n);
    return lo + (k < n ? k : n - 1);
  }
  bool chance(double p) { return uniform() < p; }
  // uniform(lo, hi) rounded to a multiple of step.
  double snapped(double lo, double hi, double step) { return std::round(uniform(lo, hi) / step) * step; }
  // An independent stream for a sub-task (its draws do not shift this one's).
  Rng fork(std::uint64_t salt) { return Rng(next() ^ splitmix64(salt)); }

 private:
  std::uint64_t state_;
};

}  // namespace stvl::worldgen

#pragma once
// splitmix64's finalizer (Steele, Lea and Flood): a bijective 64-bit mix with good avalanche, for seeds and
// counter-based random draws. (filter/ keeps its own copy: it builds on its own, without common/.)
#include <cmath>
#include <cstdint>

namespace stvl {

inline std::uint64_t splitmix64_mix(std::uint64_t x) {
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// splitmix64's step: the golden-ratio increment, then the finalizer.
inline std::uint64_t splitmix64(std::uint64_t x) { return splitmix64_mix(x + 0x9E3779B97F4A7C15ull); }

// A uniform in (0, 1) from a 64-bit word (its top 53 bits, never 0 or 1).
inline double unit_open(std::uint64_t bits) { return (static_cast<double>(bits >> 11) + 0.5) * 0x1.0p-53; }

// A standard normal from two 64-bit words (Box-Muller, the cosine branch).
inline double box_muller(std::uint64_t a, std::uint64_t b) {
  return std::sqrt(-2.0 * std::log(unit_open(a))) * std::cos(2.0 * M_PI * unit_open(b));
}

}  // namespace stvl

#pragma once
// splitmix64's finalizer (Steele, Lea and Flood): a bijective 64-bit mix with good avalanche, for seeds and
// counter-based random draws. (filter/ keeps its own copy: it builds on its own, without common/.)
#include <cstdint>

namespace stvl {

inline std::uint64_t splitmix64_mix(std::uint64_t x) {
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// splitmix64's step: the golden-ratio increment, then the finalizer.
inline std::uint64_t splitmix64(std::uint64_t x) { return splitmix64_mix(x + 0x9E3779B97F4A7C15ull); }

}  // namespace stvl

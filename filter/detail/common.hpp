#pragma once
// Host-side helpers shared by the CPU and CUDA filters: validation, layouts, threads, radix sort.
#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cstdint>
#include <thread>
#include <vector>

#include "filter/csnb.hpp"
#include "filter/detail/shared.hpp"
#include "filter/voxel_grid.hpp"

namespace stvl::filter::detail {

struct Bounds {
  float min[3] = {0, 0, 0};
  float max[3] = {0, 0, 0};
  std::uint64_t finite = 0;
};

void validate(const VoxelGridConfig& config);
void validate(const CsnbConfig& config);
void check_cloud_size(std::int64_t points);
VoxelLayout make_voxel_layout(const Bounds& bounds, double voxel_size_m, std::uint64_t points);
CsnbLayout make_csnb_layout(const Bounds& bounds, const CsnbConfig& config);
int bit_width(std::uint64_t value);

int resolve_threads(int threads);

// Number of parts worth splitting n items into (about 4096 items per thread at least).
inline int parts_for(std::size_t n, int threads, std::size_t grain = 4096) {
  return static_cast<int>(std::max<std::size_t>(1, std::min<std::size_t>(threads, n / grain + 1)));
}

// Runs fn(begin, end, part) on `threads` contiguous parts of [0, n); the caller runs the last part.
template <class Fn>
void parallel_for(std::size_t n, int threads, Fn&& fn) {
  if (threads == 1) {
    fn(std::size_t{0}, n, 0);
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  for (int t = 0; t + 1 < threads; ++t) {
    pool.emplace_back([&fn, n, threads, t] { fn(n * t / threads, n * (t + 1) / threads, t); });
  }
  fn(n * (threads - 1) / threads, n, threads - 1);
  for (auto& thread : pool) thread.join();
}

Bounds compute_bounds(const Eigen::Matrix3Xf& points, int threads);

// Stable LSD radix sort of `items` on bits [low_bit, high_bit) of key(item), 11-bit digits, parallel.
template <class T, class KeyFn>
void radix_sort(std::vector<T>& items, std::vector<T>& scratch, int low_bit, int high_bit, KeyFn key, int threads) {
  constexpr int kDigitBits = 11;
  constexpr std::size_t kBins = std::size_t{1} << kDigitBits;
  const std::size_t n = items.size();
  scratch.resize(n);
  threads = parts_for(n, threads, 65536);
  std::vector<std::array<std::size_t, kBins>> counts(threads);
  for (int shift = low_bit; shift < high_bit; shift += kDigitBits) {
    const std::uint64_t mask = (std::uint64_t{1} << std::min(kDigitBits, high_bit - shift)) - 1;
    parallel_for(n, threads, [&](std::size_t b, std::size_t e, int t) {
      auto& c = counts[t];
      c.fill(0);
      for (std::size_t i = b; i < e; ++i) ++c[(key(items[i]) >> shift) & mask];
    });
    bool trivial = false;
    std::size_t offset = 0;
    for (std::size_t d = 0; d < kBins; ++d) {
      std::size_t total = 0;
      for (int t = 0; t < threads; ++t) total += counts[t][d];
      if (total == n) trivial = true;
      for (int t = 0; t < threads; ++t) {
        const std::size_t c = counts[t][d];
        counts[t][d] = offset;
        offset += c;
      }
    }
    if (trivial) continue;  // every item has the same digit: the pass would not move anything
    parallel_for(n, threads, [&](std::size_t b, std::size_t e, int t) {
      auto& c = counts[t];
      for (std::size_t i = b; i < e; ++i) scratch[c[(key(items[i]) >> shift) & mask]++] = items[i];
    });
    items.swap(scratch);
  }
}

}  // namespace stvl::filter::detail

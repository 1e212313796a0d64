#pragma once
// Host-side helpers shared by the CPU and CUDA filters: validation, layouts, threads, radix sort.
#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cstdint>
#include <thread>
#include <utility>
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

// The AVX2 code paths run where the CPU has AVX2 (cpu_has_avx2: x86 only) and this switch is on (the
// default). Tests turn it off to check that the plain paths give the same output.
void set_simd_enabled(bool enabled);
bool simd_enabled();
bool cpu_has_avx2();

// The filters keep their work buffers per calling thread between calls (fresh multi-megabyte buffers would
// page-fault on every frame), but release them after a cloud larger than this, so that one huge cloud does not
// hold its memory for the thread's life.
constexpr std::size_t kKeepBuffersUpToPoints = 2'000'000;

// Runs `f` when the scope ends (also when it ends by an exception).
template <class F>
struct AtScopeExit {
  F f;
  ~AtScopeExit() { f(); }
};
template <class F>
AtScopeExit(F) -> AtScopeExit<F>;

// Number of parts worth splitting n items into (about 4096 items per thread at least).
inline int parts_for(std::size_t n, int threads, std::size_t grain = 4096) {
  return static_cast<int>(std::max<std::size_t>(1, std::min<std::size_t>(threads, n / grain + 1)));
}

// Runs fn(0) .. fn(parts - 1), the caller taking a share, and returns once all are done: one TBB task per part
// where stvl_filter is built with TBB (STVL_FILTER_TBB), else on a small persistent pool of worker threads
// (spawning threads when the pool is busy: another caller, or a nested call). Outputs never depend on which
// thread runs a part: every buffer a part writes is indexed by its part number.
void run_parallel(int parts, void (*fn)(void*, int), void* context);

// Runs fn(begin, end, part) on `threads` contiguous parts of [0, n).
template <class Fn>
void parallel_for(std::size_t n, int threads, Fn&& fn) {
  if (threads <= 1) {
    fn(std::size_t{0}, n, 0);
    return;
  }
  auto call = [&fn, n, threads](int t) {
    fn(n * std::size_t(t) / std::size_t(threads), n * std::size_t(t + 1) / std::size_t(threads), t);
  };
  run_parallel(
      threads, [](void* c, int t) { (*static_cast<decltype(call)*>(c))(t); }, &call);
}

Bounds compute_bounds(const Eigen::Matrix3Xf& points, int threads);

template <class T>
struct Segment {
  const T* data = nullptr;
  std::size_t size = 0;
};

// Stable LSD radix sort on bits [low_bit, high_bit) of key(item), digits of up to 12 bits, parallel. The
// input is the concatenation of `segments` (one per part of the first pass, in order); the result is
// written to `a` or `b` (both of room for the total, neither overlapping the segments unless the segments
// lie in `a`) and the pointer to it returned. The first pass always runs (it gathers the segments); later
// passes whose digit is the same for every item are skipped.
template <class T, class KeyFn>
T* radix_sort_segments(const std::vector<Segment<T>>& segments, T* a, T* b, int low_bit, int high_bit, KeyFn key,
                       int threads) {
  // Digits of at most 12 bits, as few passes as that allows, the bits spread evenly over them.
  constexpr int kMaxDigitBits = 12;
  const int passes = high_bit > low_bit ? (high_bit - low_bit + kMaxDigitBits - 1) / kMaxDigitBits : 0;
  const int kDigitBits = passes > 0 ? (high_bit - low_bit + passes - 1) / passes : 1;
  const std::size_t bins = std::size_t{1} << kDigitBits;
  std::size_t n = 0;
  for (const auto& s : segments) n += s.size;
  // 32-bit counts (clouds hold fewer than 2^32 points), `bins` per part: small sorts of small digits (a
  // bucket of the voxel grid) stay cheap to set up.
  const std::size_t slots = std::max<std::size_t>(segments.size(), std::size_t(threads));
  std::vector<std::uint32_t> counts_storage(slots * bins);
  auto counts = [&](int t) { return counts_storage.data() + std::size_t(t) * bins; };
  T* src = nullptr;
  T* dst = b;
  bool first = true;
  for (int pass = 0; pass < std::max(passes, 1); ++pass) {
    const int shift = low_bit + pass * kDigitBits;
    const int width = passes == 0 ? 0 : std::min(kDigitBits, high_bit - shift);
    const std::uint64_t mask = (std::uint64_t{1} << width) - 1;
    const int parts = first ? static_cast<int>(segments.size()) : parts_for(n, threads, 32768);
    auto part_range = [&](int t, const T*& begin, std::size_t& size) {
      if (first) {
        begin = segments[t].data;
        size = segments[t].size;
      } else {
        const std::size_t lo = n * std::size_t(t) / std::size_t(parts),
                          hi = n * std::size_t(t + 1) / std::size_t(parts);
        begin = src + lo;
        size = hi - lo;
      }
    };
    parallel_for(std::size_t(parts), parts, [&](std::size_t, std::size_t, int t) {
      std::uint32_t* c = counts(t);
      std::fill(c, c + bins, 0);
      const T* in;
      std::size_t size;
      part_range(t, in, size);
      if (width == 0) {
        c[0] = static_cast<std::uint32_t>(size);
        return;
      }
      for (std::size_t i = 0; i < size; ++i) ++c[(key(in[i]) >> shift) & mask];
    });
    bool trivial = false;
    std::uint32_t offset = 0;
    for (std::size_t d = 0; d < bins; ++d) {
      std::size_t total = 0;
      for (int t = 0; t < parts; ++t) total += counts(t)[d];
      if (total == n) trivial = true;
      for (int t = 0; t < parts; ++t) {
        const std::uint32_t c = counts(t)[d];
        counts(t)[d] = offset;
        offset += c;
      }
    }
    if (trivial && !first) continue;  // every item has the same digit: the pass would not move anything
    parallel_for(std::size_t(parts), parts, [&](std::size_t, std::size_t, int t) {
      std::uint32_t* c = counts(t);
      const T* in;
      std::size_t size;
      part_range(t, in, size);
      if (size == 0) return;
      if (trivial) {
        std::copy(in, in + size, dst + c[width == 0 ? 0 : (key(in[0]) >> shift) & mask]);
        return;
      }
      for (std::size_t i = 0; i < size; ++i) dst[c[(key(in[i]) >> shift) & mask]++] = in[i];
    });
    first = false;
    src = dst;
    dst = dst == b ? a : b;
  }
  return src;
}

// Stable LSD radix sort of `items` on bits [low_bit, high_bit) of key(item), parallel.
template <class T, class KeyFn>
void radix_sort(std::vector<T>& items, std::vector<T>& scratch, int low_bit, int high_bit, KeyFn key, int threads) {
  const std::size_t n = items.size();
  if (n == 0) return;
  scratch.resize(n);
  const int parts = parts_for(n, threads, 32768);
  std::vector<Segment<T>> segments(parts);
  for (int t = 0; t < parts; ++t) {
    const std::size_t lo = n * std::size_t(t) / std::size_t(parts), hi = n * std::size_t(t + 1) / std::size_t(parts);
    segments[t] = {items.data() + lo, hi - lo};
  }
  T* out = radix_sort_segments(segments, items.data(), scratch.data(), low_bit, high_bit, key, threads);
  if (out != items.data()) items.swap(scratch);
}

}  // namespace stvl::filter::detail

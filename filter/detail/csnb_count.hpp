#pragma once
// CSNB's neighbour counts (csnb_count.cpp): the sorted points and candidates they read, the Counter that walks
// a point's neighbour rows, and the counting loops, each on AVX2 blocks (where the CPU has AVX2) or plain ones
// with the same IEEE operations, so the same counts. The walk (csnb_walk.hpp) and the driver (csnb.cpp) use
// them.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "filter/detail/shared.hpp"

namespace stvl::filter::detail::csnb {

// A point, in sorted order (cube = index into the occupied-cube table).
struct Point {
  float x, y, z;
  std::uint32_t cube;
};

enum : std::uint8_t { kUnmarked = 1, kMarked = 2, kAmbiguous = 3 };  // what a count found for a point

// Candidate neighbours: every point, in sorted order (so per cube), padded with kPad entries that are never
// within r (x = NaN), so that counts can read whole blocks of kBlock. A candidate is live while the current
// batch starts at or before its key: the point's walk id while it may still be marked and deleted (batches
// delete only marked points the walk has passed), `never` once it cannot be (anchors, settled points).
struct Candidate {
  float x, y, z;
  std::uint32_t key;
};
// `never`: above every walk id, as the counts compare keys: signed 32-bit with AVX2 (clouds of fewer than 2^31
// points), unsigned without.
constexpr std::uint32_t kNeverAvx2 = 0x7FFFFFFF, kNeverPlain = 0xFFFFFFFF;
constexpr std::uint32_t kBlock = 8;
constexpr std::uint32_t kPad = kBlock;

inline bool bit(const std::uint64_t* bits, std::uint32_t i) { return (bits[i / 64] >> (i % 64)) & 1; }
inline void set_bit(std::uint64_t* bits, std::uint32_t i) { bits[i / 64] |= std::uint64_t{1} << (i % 64); }
// visit(i) for every set bit i of bits, in increasing order.
template <class Visit>
void for_each_bit(const std::vector<std::uint64_t>& bits, Visit&& visit) {
  for (std::size_t k = 0; k < bits.size(); ++k) {
    for (std::uint64_t word = bits[k]; word != 0; word &= word - 1)
      visit(static_cast<std::uint32_t>(k * 64 + __builtin_ctzll(word)));
  }
}

// Neighbour counts over the candidates, with early exit after every block of kBlock, the centre row (the
// point's own cube and its x-neighbours) first.
struct Counter {
  const Candidate* candidates;
  const std::uint32_t* start;  // per cube: its first candidate
  const std::uint32_t* spans;  // per cube and row: the occupied cubes [first, end) the row covers
  int rows;
  int centre_row;
  float r2;
  int threshold;

  // True when more than `threshold` candidates that `accept` takes lie closer than r to (px, py, pz) in
  // `cube`. Block::count counts one block.
  template <class Block, bool kOwnFirst = true, class Accept>
  bool exceeds(float px, float py, float pz, std::uint32_t cube, const Accept& accept) const {
    int k = 0;
    return for_blocks<kOwnFirst>(cube, [&](std::uint32_t j, std::uint32_t n) {
             k += Block::count(*this, j, n, px, py, pz, accept);
             return k > threshold ? 1 : 0;
           }) == 1;
  }
  // Calls step(first, n) on the blocks of the candidates near `cube` until it returns non-zero; returns that.
  template <bool kOwnFirst = true, class Step>
  int for_blocks(std::uint32_t cube, Step&& step) const {
    const std::uint32_t* span = spans + std::size_t(cube) * rows * 2;
    auto range = [&](std::uint32_t j, std::uint32_t e) {
      for (int verdict = 0; j < e; j += kBlock) {
        if ((verdict = step(j, std::min(kBlock, e - j))) != 0) return verdict;
      }
      return 0;
    };
    int verdict = 0;
    if (kOwnFirst) {  // most counts that stop early stop here
      const std::uint32_t own_begin = start[cube], own_end = start[cube + 1];
      verdict = range(own_begin, own_end);
      if (verdict == 0) verdict = range(start[span[2 * centre_row]], own_begin);
      if (verdict == 0) verdict = range(own_end, start[span[2 * centre_row + 1]]);
    }
    for (int r = 0; r < rows && verdict == 0; ++r) {
      if (!kOwnFirst || r != centre_row) verdict = range(start[span[2 * r]], start[span[2 * r + 1]]);
    }
    return verdict;
  }
  // A point's neighbourhood in three steps, a few points apart, each reading what the one before brought in:
  // its spans, then their starts, then the first candidates of every row.
  void prefetch_spans(std::uint32_t cube) const {
    const std::uint32_t* span = spans + std::size_t(cube) * rows * 2;
    __builtin_prefetch(span);
    __builtin_prefetch(span + 16);
    __builtin_prefetch(&start[cube]);
  }
  void prefetch_starts(std::uint32_t cube) const {
    const std::uint32_t* span = spans + std::size_t(cube) * rows * 2;
    for (int r = 0; r < rows; ++r) __builtin_prefetch(&start[span[2 * r]]);
  }
  void prefetch_rows(std::uint32_t cube) const {
    const std::uint32_t* span = spans + std::size_t(cube) * rows * 2;
    for (int r = 0; r < rows; ++r) __builtin_prefetch(candidates + start[span[2 * r]]);
    __builtin_prefetch(candidates + start[cube]);
  }
};

// True where the counts may use AVX2: the CPU has it and detail::simd_enabled().
bool avx2_supported();

// The counting loops. `avx2`: on AVX2 blocks (only where avx2_supported()), else plain ones; the same results.
// Points sure to be marked whenever the walk reaches them and sparse points (never marked), as bits by walk id,
// for the cubes [b, e); needs every candidate live.
void sure_part(bool avx2, const Counter& c, std::size_t b, std::size_t e, std::uint32_t order_size, std::uint64_t* sure,
               std::uint64_t* sparse);
// over[cube] for the anchors of cubes [b, e): more than `threshold` live neighbours after the walk.
void anchors_over(bool avx2, const Counter& anchors, const std::uint32_t* settled_near, std::size_t b, std::size_t e,
                  std::uint8_t* over);
// kMarked, kUnmarked or kAmbiguous for the walk ids ids[b, e) while the batch that starts at `start` is gathered.
void classify(bool avx2, const Counter& c, const Point* points, std::uint32_t start, const std::uint32_t* ids,
              std::size_t b, std::size_t e, std::uint8_t* result);
// Marked or not, for walk id `me`, while the batch that starts at walk id `start` is gathered.
bool marked_now(bool avx2, const Counter& c, const Point& p, std::uint32_t start, std::uint32_t me);
// detail::cube_key of n all-finite points inside the layout's box.
void cube_keys(bool avx2, const float* p, std::size_t n, const CsnbLayout& l, std::uint64_t* keys);

}  // namespace stvl::filter::detail::csnb

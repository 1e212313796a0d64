#include "filter/csnb.hpp"

#include <algorithm>
#include <limits>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "filter/detail/common.hpp"

namespace stvl::filter {

namespace {

using detail::CsnbLayout;

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

// Buffers kept per calling thread (see voxel_grid.cpp): fresh ones would page-fault on every frame.
struct Workspace {
  std::vector<std::uint64_t> items, scratch, order;
  std::vector<std::uint32_t> column, cube_key, cube_begin, spans, anchor, unsure;
  std::vector<Point> points, unsure_points;
  std::vector<Candidate> candidates;
  std::vector<std::uint64_t> sure;    // bit per walk id: marked whenever reached (find_sure)
  std::vector<std::uint64_t> sparse;  // bit per walk id: no more than max_neighbours neighbours at all
  std::vector<std::vector<std::uint64_t>> sure_parts;  // per part of find_sure: sure, sparse, sure, ...
  std::vector<std::uint8_t> is_anchor, result, claims, claimed;
  std::vector<Candidate> anchor_candidates;  // by cube, for the final claims
  std::vector<std::uint32_t> cube_index;
  std::vector<std::vector<std::uint32_t>> settled_near;  // per part: settled points near each anchor
  std::vector<std::uint64_t> settled_bits;
  std::vector<std::uint32_t> settled;  // sorted positions
  std::vector<std::vector<std::uint64_t>> near_pairs;
};

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

// Two-pass parallel fill: count(b, e) says how many outputs the part [b, e) makes, prepare(total) makes room,
// write(b, e, first) writes them from `first`; returns the total. Parts are contiguous ranges of [0, n), so
// the outputs keep the input order.
template <class Count, class Prepare, class Write>
std::size_t parallel_compact(std::size_t n, int threads, std::size_t grain, Count&& count, Prepare&& prepare,
                             Write&& write) {
  const int parts = detail::parts_for(n, threads, grain);
  std::vector<std::size_t> offset(parts + 1, 0);
  detail::parallel_for(n, parts, [&](std::size_t b, std::size_t e, int t) { offset[t + 1] = count(b, e); });
  for (int t = 0; t < parts; ++t) offset[t + 1] += offset[t];
  prepare(offset[parts]);
  detail::parallel_for(n, parts, [&](std::size_t b, std::size_t e, int t) { write(b, e, offset[t]); });
  return offset[parts];
}

#if defined(__x86_64__) || defined(__i386__)
#define STVL_CSNB_X86 1
#define STVL_AVX2 __attribute__((target("avx2")))  // not "fma": a*b+c must stay two roundings, as in sq_dist
bool avx2_supported() { return detail::cpu_has_avx2() && detail::simd_enabled(); }
#else
#define STVL_CSNB_X86 0
#define STVL_AVX2
bool avx2_supported() { return false; }
#endif

// Which candidates a count takes, by their keys (walk ids or never; the point's own key is `me`), per key and
// per 8 keys for AVX2 (keys < 2^31 there).
struct Other {  // anything but the point itself
  std::uint32_t me;
  bool operator()(std::uint32_t key) const { return key != me; }
#if STVL_CSNB_X86
  STVL_AVX2 __m256i mask(__m256i keys) const {
    return _mm256_xor_si256(_mm256_cmpeq_epi32(keys, _mm256_set1_epi32(int(me))), _mm256_set1_epi32(-1));
  }
#endif
};
struct LiveOther {  // live in the batch that starts at walk id `start`, and not the point itself
  std::uint32_t me, start;
  bool operator()(std::uint32_t key) const { return (key >= start) & (key != me); }
#if STVL_CSNB_X86
  STVL_AVX2 __m256i mask(__m256i keys) const {
    return _mm256_andnot_si256(_mm256_cmpeq_epi32(keys, _mm256_set1_epi32(int(me))),
                               _mm256_cmpgt_epi32(keys, _mm256_set1_epi32(int(start) - 1)));
  }
#endif
};

// Two counts at once for a point not yet reached by the walk (walk id `me`) while the batch that starts at
// `start` is gathered: safe neighbours, which are live whenever the walk reaches the point (anchors, settled
// points, and points later in the walk: all have larger keys), and all live neighbours.
struct SafeAndLive {
  std::uint32_t me, start;
  void operator()(std::uint32_t key, bool* safe, bool* any) const {
    *any = LiveOther{me, start}(key);
    *safe = key > me;
  }
#if STVL_CSNB_X86
  STVL_AVX2 void mask(__m256i keys, __m256i* safe, __m256i* any) const {
    *any = LiveOther{me, start}.mask(keys);
    *safe = _mm256_cmpgt_epi32(keys, _mm256_set1_epi32(int(me)));
  }
#endif
};

// Neighbour counts over the candidates, with early exit after every block of kBlock, the centre row (the
// point's own cube and its x-neighbours) first.
struct Counter {
  const Candidate* candidates;
  const std::uint32_t* start;      // per cube: its first candidate
  const std::uint32_t* spans;      // per cube and row: the occupied cubes [first, end) the row covers
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

// Candidates j .. j + n - 1 (n <= kBlock) within r of (px, py, pz) that `accept` takes, one at a time or 8
// at a time: the same IEEE operations as detail::sq_dist in both, so the same counts.
struct PlainBlock {
  template <class Accept>
  static int count(const Counter& c, std::size_t j, std::uint32_t n, float px, float py, float pz,
                   const Accept& accept) {
    int k = 0;
    for (std::uint32_t l = 0; l < n; ++l) {
      const Candidate& o = c.candidates[j + l];
      k += (detail::sq_dist(px, py, pz, o.x, o.y, o.z) < c.r2) & accept(o.key);
    }
    return k;
  }
  template <class Accept2>
  static void count2(const Counter& c, std::size_t j, std::uint32_t n, float px, float py, float pz,
                     const Accept2& accept, int* safe, int* any) {
    for (std::uint32_t l = 0; l < n; ++l) {
      const Candidate& o = c.candidates[j + l];
      bool s, a;
      accept(o.key, &s, &a);
      const bool near = detail::sq_dist(px, py, pz, o.x, o.y, o.z) < c.r2;
      *safe += near & s;
      *any += near & a;
    }
  }
};
#if STVL_CSNB_X86
struct Avx2Block {
  // kFirstLanes[n]: the lanes that hold candidates 0 .. n - 1 after the transpose.
  static constexpr unsigned kFirstLanes[9] = {0x00, 0x01, 0x11, 0x13, 0x33, 0x37, 0x77, 0x7F, 0xFF};
  template <class Accept>
  STVL_AVX2 static int count(const Counter& c, std::size_t j, std::uint32_t n, float px, float py, float pz,
                             const Accept& accept) {
    __m256 near;
    __m256i keys;
    load(c, j, px, py, pz, &near, &keys);
    const __m256 taken = _mm256_and_ps(near, _mm256_castsi256_ps(accept.mask(keys)));
    return __builtin_popcount(unsigned(_mm256_movemask_ps(taken)) & kFirstLanes[n]);
  }
  template <class Accept2>
  STVL_AVX2 static void count2(const Counter& c, std::size_t j, std::uint32_t n, float px, float py, float pz,
                               const Accept2& accept, int* safe, int* any) {
    __m256 near;
    __m256i keys, s, a;
    load(c, j, px, py, pz, &near, &keys);
    accept.mask(keys, &s, &a);
    *safe += __builtin_popcount(unsigned(_mm256_movemask_ps(_mm256_and_ps(near, _mm256_castsi256_ps(s)))) & kFirstLanes[n]);
    *any += __builtin_popcount(unsigned(_mm256_movemask_ps(_mm256_and_ps(near, _mm256_castsi256_ps(a)))) & kFirstLanes[n]);
  }
  // Lanes within r of (px, py, pz), and the keys, of candidates j .. j + 7 (reads 8 even when the block
  // holds fewer: the padding keeps that inside the array, kFirstLanes masks them out).
  STVL_AVX2 static void load(const Counter& c, std::size_t j, float px, float py, float pz, __m256* near, __m256i* keys) {
    // Two candidates per load; transposed, lanes 0..7 hold candidates 0 2 4 6 1 3 5 7.
    const float* f = reinterpret_cast<const float*>(c.candidates + j);
    const __m256 a0 = _mm256_loadu_ps(f), a1 = _mm256_loadu_ps(f + 8), a2 = _mm256_loadu_ps(f + 16),
                 a3 = _mm256_loadu_ps(f + 24);
    const __m256 t0 = _mm256_unpacklo_ps(a0, a1), t1 = _mm256_unpackhi_ps(a0, a1);
    const __m256 t2 = _mm256_unpacklo_ps(a2, a3), t3 = _mm256_unpackhi_ps(a2, a3);
    const __m256 xs = _mm256_castpd_ps(_mm256_unpacklo_pd(_mm256_castps_pd(t0), _mm256_castps_pd(t2)));
    const __m256 ys = _mm256_castpd_ps(_mm256_unpackhi_pd(_mm256_castps_pd(t0), _mm256_castps_pd(t2)));
    const __m256 zs = _mm256_castpd_ps(_mm256_unpacklo_pd(_mm256_castps_pd(t1), _mm256_castps_pd(t3)));
    *keys = _mm256_castpd_si256(_mm256_unpackhi_pd(_mm256_castps_pd(t1), _mm256_castps_pd(t3)));
    const __m256 dx = _mm256_sub_ps(_mm256_set1_ps(px), xs);
    const __m256 dy = _mm256_sub_ps(_mm256_set1_ps(py), ys);
    const __m256 dz = _mm256_sub_ps(_mm256_set1_ps(pz), zs);
    const __m256 d2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz));
    *near = _mm256_cmp_ps(d2, _mm256_set1_ps(c.r2), _CMP_LT_OQ);  // false for the NaN padding
  }
};
#endif

// Points sure to be marked whenever the walk reaches them, as bits by walk id: more than `threshold`
// neighbours that are anchors or come later in the walk (a larger walk id). Batches delete only points the
// walk has passed and anchors never, so all of these are live when the walk reaches the point. Counted in
// cube order, where the neighbour rows stay in cache, testing at most kSureBudget candidates per point: a
// point not shown sure here is classified by the walk's windows. The same pass finds the sparse points, with
// no more than `threshold` neighbours at all: never marked, so settled from the start. Needs every
// candidate live.
constexpr std::size_t kSureBudget = 128;
constexpr std::size_t kWindowBatches = 8;  // batches per window of the walk

// The counting loops, over plain or AVX2 blocks. The AVX2 entry points are compiled for AVX2 with everything
// they call inlined (flatten), and called only where the CPU has it.
template <class Block>
void sure_part(const Counter& c, std::size_t b, std::size_t e, std::uint32_t order_size, std::uint64_t* sure,
               std::uint64_t* sparse) {
  for (std::size_t cube = b; cube < e; ++cube) {
    for (std::uint32_t s = c.start[cube]; s < c.start[cube + 1]; ++s) {
      const Candidate& p = c.candidates[s];
      const std::uint32_t me = p.key;
      if (me >= order_size) continue;  // an anchor
      int later = 0, any = 0;
      std::size_t tested = 0;
      const int verdict = c.for_blocks(std::uint32_t(cube), [&](std::uint32_t j, std::uint32_t n) {
        Block::count2(c, j, n, p.x, p.y, p.z, SafeAndLive{me, 0}, &later, &any);
        tested += n;
        return later > c.threshold ? 1 : tested >= kSureBudget ? -1 : 0;
      });
      if (verdict == 1) set_bit(sure, me);
      if (verdict == 0 && any <= c.threshold) set_bit(sparse, me);
    }
  }
}

// Anchors with more than `threshold` live neighbours after the walk: `anchors` counts over the anchors alone
// (candidate c = the anchor of cube c), settled_near[c] the settled points near anchor c.
template <class Block>
void anchors_over(const Counter& anchors, const std::uint32_t* settled_near, std::size_t b, std::size_t e,
                  std::uint8_t* over) {
  Counter rest = anchors;
  for (std::size_t cube = b; cube < e; ++cube) {
    const Candidate& a = anchors.candidates[cube];
    rest.threshold = anchors.threshold - int(std::min<std::uint32_t>(settled_near[cube], 1u << 30));
    // Rows only: the anchor is alone in its cube.
    over[cube] = rest.threshold < 0 || rest.exceeds<Block, false>(a.x, a.y, a.z, std::uint32_t(cube), Other{a.key});
  }
}

// For the walk ids ids[b, e) (points[k]: the point of ids[k]), while the batch that starts at walk id `start`
// is gathered: result[k] is kMarked when more than `threshold` safe neighbours (SafeAndLive), kUnmarked when
// no more than `threshold` live ones, else kAmbiguous.
template <class Block>
void classify(const Counter& c, const Point* points, std::uint32_t start, const std::uint32_t* ids, std::size_t b,
              std::size_t e, std::uint8_t* result) {
  for (std::size_t k = b; k < e; ++k) {
    if (k + 12 < e) c.prefetch_spans(points[k + 12].cube);
    if (k + 8 < e) c.prefetch_starts(points[k + 8].cube);
    if (k + 4 < e) c.prefetch_rows(points[k + 4].cube);
    const std::uint32_t me = ids[k];
    const Point p = points[k];
    int safe = 0, any = 0;
    const SafeAndLive accept{me, start};
    const bool marked = c.for_blocks(p.cube, [&](std::uint32_t j, std::uint32_t n) {
      Block::count2(c, j, n, p.x, p.y, p.z, accept, &safe, &any);
      return safe > c.threshold ? 1 : 0;
    }) == 1;
    result[k] = marked ? kMarked : any > c.threshold ? kAmbiguous : kUnmarked;
  }
}

// Marked or not, for walk id `me`, while the batch that starts at walk id `start` is gathered.
template <class Block>
bool marked_now(const Counter& c, const Point& p, std::uint32_t start, std::uint32_t me) {
  return c.exceeds<Block>(p.x, p.y, p.z, p.cube, LiveOther{me, start});
}

#if STVL_CSNB_X86
#define STVL_AVX2_ENTRY(result, name, params, args) \
  STVL_AVX2 __attribute__((flatten)) result name##_avx2 params { return name<Avx2Block> args; }
#else
#define STVL_AVX2_ENTRY(result, name, params, args) \
  result name##_avx2 params { return name<PlainBlock> args; }
#endif
STVL_AVX2_ENTRY(void, sure_part, (const Counter& c, std::size_t b, std::size_t e, std::uint32_t o, std::uint64_t* sure,
                            std::uint64_t* sparse), (c, b, e, o, sure, sparse))
STVL_AVX2_ENTRY(void, anchors_over, (const Counter& c, const std::uint32_t* near, std::size_t b, std::size_t e,
                               std::uint8_t* over), (c, near, b, e, over))
STVL_AVX2_ENTRY(void, classify, (const Counter& c, const Point* p, std::uint32_t start, const std::uint32_t* ids,
                                  std::size_t b, std::size_t e, std::uint8_t* result),
                (c, p, start, ids, b, e, result))
STVL_AVX2_ENTRY(bool, marked_now, (const Counter& c, const Point& p, std::uint32_t start, std::uint32_t me),
                (c, p, start, me))
#undef STVL_AVX2_ENTRY

// Cube boundaries of `parts` parts with about equal candidates (start: each cube's first), rather than equal
// cubes: dense cubes cost more.
std::vector<std::size_t> split_cubes(const std::uint32_t* start, std::size_t cubes, int parts) {
  std::vector<std::size_t> part(parts + 1, cubes);
  for (int t = 0; t < parts; ++t) {
    const std::uint64_t target = std::uint64_t(start[cubes]) * std::uint64_t(t) / std::uint64_t(parts);
    part[t] = static_cast<std::size_t>(std::lower_bound(start, start + cubes, target) - start);
  }
  return part;
}

void find_sure(Workspace& w, const Counter& counter, std::size_t cubes, std::uint32_t order_size, bool avx2,
               int threads) {
  const std::size_t words = (std::size_t(order_size) + 63) / 64;
  const int parts = detail::parts_for(cubes, threads, 1024);
  w.sure_parts.resize(2 * parts);
  const std::vector<std::size_t> part = split_cubes(counter.start, cubes, parts);
  detail::parallel_for(std::size_t(parts), parts, [&](std::size_t, std::size_t, int t) {
    const std::size_t b = part[t], e = part[t + 1];
    std::vector<std::uint64_t>& sure = w.sure_parts[2 * t];  // bitmaps per part: no shared cache lines
    std::vector<std::uint64_t>& sparse = w.sure_parts[2 * t + 1];
    sure.assign(words, 0);
    sparse.assign(words, 0);
    if (avx2)
      sure_part_avx2(counter, b, e, order_size, sure.data(), sparse.data());
    else
      sure_part<PlainBlock>(counter, b, e, order_size, sure.data(), sparse.data());
  });
  w.sure.assign(words, 0);
  w.sparse.assign(words, 0);
  detail::parallel_for(words, detail::parts_for(words, threads, 4096), [&](std::size_t b, std::size_t e, int) {
    for (int t = 0; t < parts; ++t) {
      for (std::size_t i = b; i < e; ++i) {
        w.sure[i] |= w.sure_parts[2 * t][i];
        w.sparse[i] |= w.sure_parts[2 * t + 1][i];
      }
    }
  });
}

// Sizes `candidates` to n followed by kPad entries never within r.
void pad(std::vector<Candidate>& candidates, std::size_t n) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  candidates.resize(n + kPad);
  std::fill(candidates.begin() + n, candidates.end(), Candidate{nan, nan, nan, 0});
}

// The candidates: every point, keyed by its walk id (never for anchors).
void init_candidates(Workspace& w, std::size_t order_size, std::uint32_t never, int threads) {
  const std::size_t m = w.points.size();
  pad(w.candidates, m);
  detail::parallel_for(m, detail::parts_for(m, threads, 16384), [&](std::size_t b, std::size_t e, int) {
    for (std::size_t s = b; s < e; ++s) w.candidates[s] = {w.points[s].x, w.points[s].y, w.points[s].z, never};
  });
  detail::parallel_for(order_size, detail::parts_for(order_size, threads, 16384), [&](std::size_t b, std::size_t e, int) {
    for (std::size_t i = b; i < e; ++i) {
      if (i + 16 < e) __builtin_prefetch(&w.candidates[std::uint32_t(w.order[i + 16])], 1);  // a scatter
      w.candidates[std::uint32_t(w.order[i])].key = static_cast<std::uint32_t>(i);
    }
  });
}

// detail::cube_key of n all-finite points inside the layout's box (so the quotients are in [0, 2^9] and fit
// 32-bit integers: the same floor as detail::floor_div), as 32-bit arithmetic that vectorises.
inline void cube_keys(const float* p, std::size_t n, const CsnbLayout& l, std::uint64_t* keys) {
  const int bits = l.grid_exponent;
  const std::int32_t top = (1 << bits) - 1;
  const double min_x = l.min_m[0], min_y = l.min_m[1], min_z = l.min_m[2], edge = l.cube_edge_m;
  auto axis = [&](float v, double min) {
    const double q = (double(v) - min) / edge;
    const std::int32_t t = static_cast<std::int32_t>(q);
    return std::min(std::max(t - std::int32_t(double(t) > q), 0), top);
  };
  for (std::size_t i = 0; i < n; ++i) {
    keys[i] = std::uint32_t(axis(p[3 * i], min_x)) | std::uint32_t(axis(p[3 * i + 1], min_y)) << bits |
              std::uint32_t(axis(p[3 * i + 2], min_z)) << (2 * bits);
  }
}
#if STVL_CSNB_X86
STVL_AVX2 __attribute__((flatten)) void cube_keys_avx2(const float* p, std::size_t n, const CsnbLayout& l,
                                                       std::uint64_t* keys) {
  cube_keys(p, n, l, keys);
}
#else
void cube_keys_avx2(const float* p, std::size_t n, const CsnbLayout& l, std::uint64_t* keys) {
  cube_keys(p, n, l, keys);
}
#endif

// spans[(c * rows + r) * 2 + {0, 1}]: the occupied cubes [first, end) in row r (detail::csnb_row) of cube c,
// for the cubes c in [b, e) of the sorted `keys` (keys[cubes] = UINT32_MAX). A row's key range moves up with
// the cube's key, so per row one pair of pointers walks the table (after a binary search at b).
void find_spans(const CsnbLayout& l, const std::uint32_t* keys, std::size_t cubes, std::size_t b, std::size_t e,
                std::uint32_t* spans) {
  const int rows = detail::csnb_rows(l), side = 2 * l.reach + 1, bits = l.grid_exponent, top = (1 << bits) - 1;
  const std::uint32_t count = static_cast<std::uint32_t>(cubes);
  // detail::csnb_row with each row's offsets worked out once (it divides by `side` per call); per row, the
  // pointer pair and whether it was placed yet.
  std::vector<int> dy(rows), dz(rows);
  std::vector<std::uint32_t> first(rows, 0), end(rows, 0);
  std::vector<char> placed(rows, 0);
  for (int r = 0; r < rows; ++r) {
    dy[r] = r % side - l.reach;
    dz[r] = r / side - l.reach;
  }
  for (std::size_t c = b; c < e; ++c) {
    const int key = int(keys[c]), x = key & top, y = (key >> bits) & top, z = (key >> (2 * bits)) & top;
    const std::uint32_t x0 = std::uint32_t(std::max(x - l.reach, 0)), x1 = std::uint32_t(std::min(x + l.reach, top));
    std::uint32_t* span = spans + c * rows * 2;
    // The next cube of the same row as the last: every row's bounds rise by at most 1 and keys are distinct,
    // so each pointer moves by at most one cube.
    const bool next_in_row = c > b && x != 0 && keys[c - 1] == std::uint32_t(key - 1);
    for (int r = 0; r < rows; ++r) {
      const int ry = y + dy[r], rz = z + dz[r];
      if (ry < 0 || ry > top || rz < 0 || rz > top) {
        span[2 * r] = span[2 * r + 1] = 0;
        continue;
      }
      const std::uint32_t base = std::uint32_t(ry << bits) | std::uint32_t(rz << (2 * bits));
      const std::uint32_t lo = base | x0, hi = base | x1;
      std::uint32_t c0 = first[r], c1 = end[r];
      if (next_in_row) {
        c0 += keys[c0] < lo;
        c1 = std::max(c1, c0);
        c1 += keys[c1] <= hi;
        first[r] = span[2 * r] = c0;
        end[r] = span[2 * r + 1] = c1;
        continue;
      }
      if (!placed[r]) {
        c0 = detail::search_keys(keys, count, lo, false);
        c1 = detail::search_keys(keys, count, hi, true);
        placed[r] = 1;
      }
      // keys[count] is a sentinel above every key. The pointers mostly move by 0 to 3: steps without branches
      // first (a loop's exit would mispredict on almost every cube), a loop for the rest.
      c0 += keys[c0] < lo;
      c0 += keys[c0] < lo;
      while (keys[c0] < lo) ++c0;
      c1 = std::max(c1, c0);
      c1 += keys[c1] <= hi;
      c1 += keys[c1] <= hi;
      c1 += keys[c1] <= hi;
      while (keys[c1] <= hi) ++c1;
      first[r] = span[2 * r] = c0;
      end[r] = span[2 * r + 1] = c1;
    }
  }
}

// Settles the point of walk id j: live to the end, never deleted.
void settle(Workspace& w, std::uint32_t j, std::uint32_t never) {
  const std::uint32_t s = static_cast<std::uint32_t>(w.order[j]);  // its sorted position
  w.candidates[s].key = never;
  set_bit(w.settled_bits.data(), s);
}

// Set bits of `bits` in [from, to).
std::size_t count_bits(const std::uint64_t* bits, std::size_t from, std::size_t to) {
  if (from >= to) return 0;
  const std::size_t first = from / 64, last = (to - 1) / 64;
  const std::uint64_t head = ~std::uint64_t{0} << (from % 64), tail = ~std::uint64_t{0} >> (63 - (to - 1) % 64);
  if (first == last) return std::size_t(__builtin_popcountll(bits[first] & head & tail));
  std::size_t n = std::size_t(__builtin_popcountll(bits[first] & head)) + std::size_t(__builtin_popcountll(bits[last] & tail));
  for (std::size_t k = first + 1; k < last; ++k) n += std::size_t(__builtin_popcountll(bits[k]));
  return n;
}
// The position of the k-th (from 1) set bit at or after `from` (there must be one).
std::size_t select_bit(const std::uint64_t* bits, std::size_t from, std::size_t k) {
  std::size_t word = from / 64;
  std::uint64_t v = bits[word] & (~std::uint64_t{0} << (from % 64));
  for (std::size_t c; (c = std::size_t(__builtin_popcountll(v))) < k; v = bits[++word]) k -= c;
  for (; k > 1; --k) v &= v - 1;
  return word * 64 + std::size_t(__builtin_ctzll(v));
}

// The walk, over the points neither sure nor sparse (w.unsure, by walk id) in windows of about
// kWindowBatches batches; the sure points in between are counted from their bits, as marks that fill the
// batches. Points of a window are first classified in parallel when it opens (classify): with more than
// max_neighbours safe neighbours (anchors, settled, later in the walk: none can be deleted before the walk
// reaches the point) they are marked whenever reached; with no more than that many live ones they are
// unmarked then (counts only fall) and settled; the rest (ambiguous) are counted exactly when the walk
// reaches them, in the batch of that moment. A batch is deleted when the mark after its K-th arrives, which
// starts the next: nothing needs doing then but moving `start`, since the candidates' keys say who is live.
void walk(Workspace& w, Counter& counter, std::size_t order_size, std::size_t K, std::uint32_t never, bool avx2,
          int threads) {
  const std::uint64_t* sure = w.sure.data();
  const std::size_t unsure = w.unsure.size();
  w.result.resize(unsure);
  std::uint32_t start = 0;     // walk id where the current batch starts
  std::size_t in_batch = 0;    // marks in it
  std::size_t marks = 0;       // marks so far
  std::size_t window_end = 0;  // index into w.unsure
  auto marked_exactly = [&](std::size_t k) {
    const std::uint32_t j = w.unsure[k];
    const Point& p = w.unsure_points[k];
    return avx2 ? marked_now_avx2(counter, p, start, j) : marked_now<PlainBlock>(counter, p, start, j);
  };
  // The unsure points from index `from` of w.unsure that lie within about kWindowBatches batches.
  auto open_window = [&](std::size_t from) {
    const std::uint32_t first = w.unsure[from];
    const double rate = first == 0 ? 1.0 : double(marks) / double(first);  // marks per walk position so far
    const double span = double(kWindowBatches * (K + 1)) / std::max(rate, 1e-3);
    const double last = std::min(double(order_size), double(first) + std::max(span, 256.0));
    window_end = from;
    while (window_end < unsure && double(w.unsure[window_end]) < last) ++window_end;
    const std::size_t n = window_end - from;
    detail::parallel_for(n, detail::parts_for(n, threads, 128), [&](std::size_t b, std::size_t e, int) {
      if (avx2)
        classify_avx2(counter, w.unsure_points.data() + from, start, w.unsure.data() + from, b, e,
                      w.result.data() + from);
      else
        classify<PlainBlock>(counter, w.unsure_points.data() + from, start, w.unsure.data() + from, b, e,
                             w.result.data() + from);
    });
  };
  // n more marks, the sure points at walk ids [from, to): where the last batch they start begins.
  auto sure_marks = [&](std::size_t from, std::size_t to) {
    const std::size_t n = count_bits(sure, from, to);
    marks += n;
    if (in_batch + n <= K) {
      in_batch += n;
      return;
    }
    const std::size_t first = K - in_batch + 1;  // the first of them that starts a batch (from 1), then every K
    const std::size_t last = first + (n - first) / K * K;
    start = static_cast<std::uint32_t>(select_bit(sure, from, last));
    in_batch = n - last + 1;
  };
  std::size_t previous = 0;  // walk id after the last unsure point
  for (std::size_t k = 0; k < unsure; ++k) {
    const std::uint32_t j = w.unsure[k];
    sure_marks(previous, j);
    previous = std::size_t(j) + 1;
    if (k >= window_end) open_window(k);
    // Marked in the current batch? The window's verdicts hold whatever was deleted since it opened.
    const std::uint8_t verdict = w.result[k];
    bool marked = verdict == kMarked || (verdict == kAmbiguous && marked_exactly(k));
    if (marked && in_batch == K) {  // j is the (K+1)-th mark: the batch is deleted and j counted again
      start = j;
      in_batch = 0;
      marked = verdict == kMarked || marked_exactly(k);
    }
    if (marked) {
      ++in_batch;
      ++marks;
      continue;
    }
    settle(w, j, never);
  }
}

// Anchors still over the threshold (on the final live set) take their non-anchor neighbours with them. All
// live points are now anchors or settled: an anchor's count is the anchors near it, counted over the
// anchors alone (one per cube, so cube ranges are anchor ranges), plus the settled points near it.
void claim(Workspace& w, const Counter& counter, std::size_t cubes, bool avx2, int threads) {
  const int cube_parts = detail::parts_for(cubes, threads, 1024);
  pad(w.anchor_candidates, cubes);
  w.cube_index.resize(cubes + 1);
  detail::parallel_for(cubes + 1, cube_parts, [&](std::size_t b, std::size_t e, int) {
    for (std::size_t c = b; c < e; ++c) {
      w.cube_index[c] = static_cast<std::uint32_t>(c);
      if (c == cubes) break;
      const Point& a = w.points[w.anchor[c]];
      w.anchor_candidates[c] = {a.x, a.y, a.z, static_cast<std::uint32_t>(c)};
    }
  });
  const int rows = counter.rows;
  const Counter anchors{w.anchor_candidates.data(), w.cube_index.data(), w.spans.data(), rows, counter.centre_row,
                        counter.r2, counter.threshold};
  // The anchors near a settled point (sorted position s).
  auto near_anchors = [&](std::size_t s, auto&& visit) {
    const Point& q = w.points[s];
    const std::uint32_t* span = &w.spans[std::size_t(q.cube) * rows * 2];
    for (int r = 0; r < rows; ++r) {
      for (std::uint32_t c = span[2 * r]; c < span[2 * r + 1]; ++c) {
        const Candidate& a = w.anchor_candidates[c];
        if (detail::sq_dist(q.x, q.y, q.z, a.x, a.y, a.z) < counter.r2) visit(c);
      }
    }
  };
  // The settled points (set by the walk as bits by sorted position), listed in cube order.
  w.settled.clear();
  for_each_bit(w.settled_bits, [&](std::uint32_t s) { w.settled.push_back(s); });
  const std::size_t settled_count = w.settled.size();
  const int settled_parts = detail::parts_for(settled_count, threads, 2048);
  w.settled_near.resize(settled_parts);
  w.near_pairs.resize(settled_parts);
  detail::parallel_for(settled_count, settled_parts, [&](std::size_t b, std::size_t e, int t) {
    std::vector<std::uint32_t>& near = w.settled_near[t];  // per part: no shared counters
    std::vector<std::uint64_t>& pairs = w.near_pairs[t];   // (settled point, anchor), for the claims below
    near.assign(cubes, 0);
    pairs.clear();
    for (std::size_t k = b; k < e; ++k) {
      if (k + 8 < e) anchors.prefetch_spans(w.points[w.settled[k + 8]].cube);
      if (k + 4 < e) anchors.prefetch_rows(w.points[w.settled[k + 4]].cube);
      near_anchors(w.settled[k], [&](std::uint32_t c) {
        ++near[c];
        pairs.push_back(std::uint64_t{w.settled[k]} << 32 | c);
      });
    }
  });
  for (int t = 1; t < settled_parts; ++t)
    for (std::size_t c = 0; c < cubes; ++c) w.settled_near[0][c] += w.settled_near[t][c];
  w.claims.resize(cubes);
  detail::parallel_for(cubes, cube_parts, [&](std::size_t b, std::size_t e, int) {
    if (avx2)
      anchors_over_avx2(anchors, w.settled_near[0].data(), b, e, w.claims.data());
    else
      anchors_over<PlainBlock>(anchors, w.settled_near[0].data(), b, e, w.claims.data());
  });
  w.claimed.assign(w.points.size(), 0);
  detail::parallel_for(std::size_t(settled_parts), settled_parts, [&](std::size_t, std::size_t, int t) {
    for (const std::uint64_t pair : w.near_pairs[t]) {  // a settled point is in one part only
      if (w.claims[std::uint32_t(pair)]) w.claimed[pair >> 32] = 1;
    }
  });
}

}  // namespace

Eigen::Matrix3Xf csnb(const Eigen::Matrix3Xf& points, const CsnbConfig& config, int threads) {
  detail::validate(config);
  detail::check_cloud_size(points.cols());
  threads = detail::resolve_threads(threads);
  const detail::Bounds bounds = detail::compute_bounds(points, threads);
  if (bounds.finite == 0) return Eigen::Matrix3Xf(3, 0);
  const CsnbLayout layout = detail::make_csnb_layout(bounds, config);
  const std::size_t n = static_cast<std::size_t>(points.cols());
  const std::size_t m = bounds.finite;
  const float* p = points.data();
  const int key_bits = 3 * layout.grid_exponent;
  thread_local Workspace workspace;
  Workspace& w = workspace;  // named through a reference: the pool's workers must see the caller's buffers
  const detail::AtScopeExit release{[&] {
    if (n > detail::kKeepBuffersUpToPoints) w = Workspace{};
  }};
  const bool avx2 = avx2_supported() && m < (std::size_t{1} << 31);  // ids compared as signed 32-bit

  // The finite points as (cube key << 32 | index), in index order, then stably sorted by key.
  w.items.resize(n);
  w.scratch.resize(n);
  const int parts = detail::parts_for(n, threads, 16384);
  std::vector<detail::Segment<std::uint64_t>> segments(parts);
  const bool all_finite = m == n;
  detail::parallel_for(n, parts, [&](std::size_t b, std::size_t e, int t) {
    std::uint64_t* out = w.items.data() + b;
    std::size_t count = 0;
    if (all_finite) {
      if (avx2)
        cube_keys_avx2(p + 3 * b, e - b, layout, out);
      else
        cube_keys(p + 3 * b, e - b, layout, out);
      for (std::size_t i = b; i < e; ++i) out[i - b] = out[i - b] << 32 | i;
      count = e - b;
    } else {
      for (std::size_t i = b; i < e; ++i) {
        const float x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
        if (detail::finite3(x, y, z)) out[count++] = std::uint64_t{detail::cube_key(layout, x, y, z)} << 32 | i;
      }
    }
    segments[t] = {out, count};
  });
  const std::uint64_t* sorted = detail::radix_sort_segments(segments, w.items.data(), w.scratch.data(), 32,
                                                            32 + key_bits, [](std::uint64_t v) { return v; }, threads);

  // Sorted points, and the cube table: a cube starts wherever the key changes.
  auto key_at = [&](std::size_t s) { return static_cast<std::uint32_t>(sorted[s] >> 32); };
  auto opens_cube = [&](std::size_t s) { return s == 0 || key_at(s) != key_at(s - 1); };
  const int point_parts = detail::parts_for(m, threads, 16384);
  std::vector<std::size_t> cube_offset(point_parts + 1, 0);
  detail::parallel_for(m, point_parts, [&](std::size_t b, std::size_t e, int t) {
    std::size_t opened = 0;
    for (std::size_t s = b; s < e; ++s) opened += opens_cube(s);
    cube_offset[t + 1] = opened;
  });
  for (int t = 0; t < point_parts; ++t) cube_offset[t + 1] += cube_offset[t];
  const std::size_t cubes = cube_offset[point_parts];
  w.points.resize(m);
  w.column.resize(m);
  w.cube_key.resize(cubes + 1);
  w.cube_key[cubes] = std::numeric_limits<std::uint32_t>::max();  // a sentinel for find_spans
  w.cube_begin.resize(cubes + 1);
  detail::parallel_for(m, point_parts, [&](std::size_t b, std::size_t e, int t) {
    std::size_t c = cube_offset[t];
    for (std::size_t s = b; s < e; ++s) {
      if (opens_cube(s)) {
        w.cube_key[c] = key_at(s);
        w.cube_begin[c++] = static_cast<std::uint32_t>(s);
      }
      if (s + 16 < e) __builtin_prefetch(p + 3 * static_cast<std::uint32_t>(sorted[s + 16]));  // a gather
      const std::size_t i = static_cast<std::uint32_t>(sorted[s]);
      w.points[s] = {p[3 * i], p[3 * i + 1], p[3 * i + 2], static_cast<std::uint32_t>(c - 1)};
      w.column[s] = static_cast<std::uint32_t>(i);
    }
  });
  w.cube_begin[cubes] = static_cast<std::uint32_t>(m);

  // Per cube and row (detail::csnb_row), the range of occupied cubes the row covers; the anchor: the point
  // nearest the cube centre, ties to the earliest sorted position.
  const int rows = detail::csnb_rows(layout);
  const int side = 2 * layout.reach + 1;
  w.spans.resize(cubes * rows * 2);
  w.anchor.resize(cubes);
  w.is_anchor.assign(m, 0);
  const int cube_parts = detail::parts_for(cubes, threads, 1024);
  detail::parallel_for(cubes, cube_parts, [&](std::size_t b, std::size_t e, int) {
    find_spans(layout, w.cube_key.data(), cubes, b, e, w.spans.data());
    const Point* q = w.points.data();
    for (std::size_t c = b; c < e; ++c) {
      std::uint32_t best = w.cube_begin[c];
      double best_d = detail::centre_sq_dist(layout, w.cube_key[c], q[best].x, q[best].y, q[best].z);
      for (std::uint32_t s = best + 1; s < w.cube_begin[c + 1]; ++s) {
        const double d = detail::centre_sq_dist(layout, w.cube_key[c], q[s].x, q[s].y, q[s].z);
        if (d < best_d) {
          best_d = d;
          best = s;
        }
      }
      w.anchor[c] = best;
      w.is_anchor[best] = 1;
    }
  });

  // Batches follow one random order of the non-anchor points, fixed by the seed. A point that is not marked
  // can never be marked again (counts only fall), and deleted points never return, so the points the walk
  // has passed are settled, and the first K marked points after the cursor are a uniformly random K-subset
  // of all marked points: the same law as drawing K at random in every iteration, without a full pass each.
  // A point's mark is counted when the walk reaches it, on the live set of that moment (the batch being
  // gathered is deleted only once complete), which is exactly what per-point neighbour counts kept up to
  // date by decrements would say; a point found unmarked stays settled.
  const std::size_t order_size = parallel_compact(
      m, threads, 16384,
      [&](std::size_t b, std::size_t e) {
        std::size_t count = 0;
        for (std::size_t s = b; s < e; ++s) count += !w.is_anchor[s];
        return count;
      },
      [](std::size_t) {},
      [&](std::size_t b, std::size_t e, std::size_t first) {
        for (std::size_t s = b; s < e; ++s) {
          if (w.is_anchor[s]) continue;
          w.items[first++] = detail::csnb_priority(config.seed, w.column[s], static_cast<std::uint32_t>(s));
        }
      });
  w.order.assign(w.items.begin(), w.items.begin() + order_size);
  detail::radix_sort(w.order, w.scratch, 32, 64, [](std::uint64_t v) { return v; }, threads);
  const std::uint32_t never = avx2 ? kNeverAvx2 : kNeverPlain;
  init_candidates(w, order_size, never, threads);
  Counter counter{w.candidates.data(), w.cube_begin.data(), w.spans.data(),
                  rows, layout.reach + layout.reach * side, layout.radius_sq, config.max_neighbours};
  find_sure(w, counter, cubes, std::uint32_t(order_size), avx2, threads);

  // Sparse points are settled from the start; the rest that are not sure go through the walk.
  w.settled_bits.assign((m + 63) / 64, 0);
  for_each_bit(w.sparse, [&](std::uint32_t j) { settle(w, j, never); });
  w.unsure.clear();
  for (std::size_t k = 0; k < w.sure.size(); ++k) {
    for (std::uint64_t word = ~(w.sure[k] | w.sparse[k]); word != 0; word &= word - 1) {
      const std::size_t j = k * 64 + std::size_t(__builtin_ctzll(word));
      if (j >= order_size) break;  // the last word's unused bits
      w.unsure.push_back(static_cast<std::uint32_t>(j));
    }
  }
  w.unsure_points.resize(w.unsure.size());
  for (std::size_t k = 0; k < w.unsure.size(); ++k) w.unsure_points[k] = w.points[std::uint32_t(w.order[w.unsure[k]])];
  walk(w, counter, order_size, static_cast<std::size_t>(config.batch_size), never, avx2, threads);
  claim(w, counter, cubes, avx2, threads);

  const Point* q = w.points.data();

  // Kept points in sorted order.
  w.result.resize(m);
  Eigen::Matrix3Xf out;
  parallel_compact(
      m, threads, 16384,
      [&](std::size_t b, std::size_t e) {
        std::size_t kept = 0;
        for (std::size_t s = b; s < e; ++s) {  // the anchors, and the settled points no claim deleted
          w.result[s] = w.is_anchor[s] || (bit(w.settled_bits.data(), std::uint32_t(s)) && !w.claimed[s]);
          kept += w.result[s];
        }
        return kept;
      },
      [&](std::size_t kept) { out.resize(3, static_cast<Eigen::Index>(kept)); },
      [&](std::size_t b, std::size_t e, std::size_t first) {
        float* o = out.data() + 3 * first;
        for (std::size_t s = b; s < e; ++s) {
          if (!w.result[s]) continue;
          o[0] = q[s].x;
          o[1] = q[s].y;
          o[2] = q[s].z;
          o += 3;
        }
      });
  return out;
}

}  // namespace stvl::filter

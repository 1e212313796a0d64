#include "filter/detail/csnb_count.hpp"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "filter/detail/common.hpp"

namespace stvl::filter::detail::csnb {

#if defined(__x86_64__) || defined(__i386__)
#define STVL_CSNB_X86 1
#define STVL_AVX2 __attribute__((target("avx2")))  // not "fma": a*b+c must stay two roundings, as in sq_dist
bool avx2_supported() { return detail::cpu_has_avx2() && detail::simd_enabled(); }
#else
#define STVL_CSNB_X86 0
#define STVL_AVX2
bool avx2_supported() { return false; }
#endif

namespace {

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
    *safe +=
        __builtin_popcount(unsigned(_mm256_movemask_ps(_mm256_and_ps(near, _mm256_castsi256_ps(s)))) & kFirstLanes[n]);
    *any +=
        __builtin_popcount(unsigned(_mm256_movemask_ps(_mm256_and_ps(near, _mm256_castsi256_ps(a)))) & kFirstLanes[n]);
  }
  // Lanes within r of (px, py, pz), and the keys, of candidates j .. j + 7 (reads 8 even when the block
  // holds fewer: the padding keeps that inside the array, kFirstLanes masks them out).
  STVL_AVX2 static void load(const Counter& c, std::size_t j, float px, float py, float pz, __m256* near,
                             __m256i* keys) {
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

namespace loops {

// The counting loops, over plain or AVX2 blocks (the entry points below choose).
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

}  // namespace loops

}  // namespace

// The entry points: name(bool avx2, params...) runs loops::name on AVX2 blocks, compiled for AVX2 with everything
// it calls inlined (flatten), or on plain ones.
#define STVL_WITH_AVX2_FLAG(...) (bool avx2, __VA_ARGS__)
#if STVL_CSNB_X86
#define STVL_CSNB_ENTRY(result, name, params, args)                                                           \
  STVL_AVX2 __attribute__((flatten)) static result name##_avx2 params { return loops::name<Avx2Block> args; } \
  result name STVL_WITH_AVX2_FLAG params { return avx2 ? name##_avx2 args : loops::name<PlainBlock> args; }
#else
#define STVL_CSNB_ENTRY(result, name, params, args) \
  result name STVL_WITH_AVX2_FLAG params {          \
    (void)avx2;                                     \
    return loops::name<PlainBlock> args;            \
  }
#endif
STVL_CSNB_ENTRY(void, sure_part,
                (const Counter& c, std::size_t b, std::size_t e, std::uint32_t o, std::uint64_t* sure,
                 std::uint64_t* sparse),
                (c, b, e, o, sure, sparse))
STVL_CSNB_ENTRY(void, anchors_over,
                (const Counter& c, const std::uint32_t* near, std::size_t b, std::size_t e, std::uint8_t* over),
                (c, near, b, e, over))
STVL_CSNB_ENTRY(void, classify,
                (const Counter& c, const Point* p, std::uint32_t start, const std::uint32_t* ids, std::size_t b,
                 std::size_t e, std::uint8_t* result),
                (c, p, start, ids, b, e, result))
STVL_CSNB_ENTRY(bool, marked_now, (const Counter& c, const Point& p, std::uint32_t start, std::uint32_t me),
                (c, p, start, me))
#undef STVL_CSNB_ENTRY
#undef STVL_WITH_AVX2_FLAG

#if STVL_CSNB_X86
STVL_AVX2 __attribute__((flatten)) static void cube_keys_avx2(const float* p, std::size_t n, const CsnbLayout& l,
                                                              std::uint64_t* keys) {
  loops::cube_keys(p, n, l, keys);
}
void cube_keys(bool avx2, const float* p, std::size_t n, const CsnbLayout& l, std::uint64_t* keys) {
  if (avx2) cube_keys_avx2(p, n, l, keys);
  else loops::cube_keys(p, n, l, keys);
}
#else
void cube_keys(bool, const float* p, std::size_t n, const CsnbLayout& l, std::uint64_t* keys) {
  loops::cube_keys(p, n, l, keys);
}
#endif

}  // namespace stvl::filter::detail::csnb

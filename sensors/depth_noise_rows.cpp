#include "sensors/depth_noise_rows.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>

#include "common/splitmix.hpp"

// Compiled with -ffp-contract=off (sensors/CMakeLists.txt): every double operation rounds once, as written, in
// every instruction set, so the vector passes give the plain per-pixel code's floats bit for bit.

namespace stvl::sensors::noise_rows {
namespace {

constexpr uint64_t kGolden = 0x9E3779B97F4A7C15ULL;
constexpr int kNormalMask = 4095;
constexpr int kChunk = 512;  // pixels per pass: the passes' arrays stay on the stack and in L1

// splitmix64 over the counter (index, stream): one mix per draw.
inline uint64_t draw(uint64_t key, uint64_t index, Stream stream) {
  return splitmix64_mix(key + (index * kStreams + stream + 1) * kGolden);
}

inline double uniform(uint64_t key, uint64_t index, Stream stream) {
  return double(draw(key, index, stream) >> 11) * 0x1.0p-53;  // [0, 1)
}

// double(int64_t(x)) for 0 <= x < 2^63 without the conversion (which vectorizes only with AVX-512 DQ): below 2^52,
// adding and subtracting 2^52 rounds to the nearest integer, one less when that is above x; from 2^52 on every
// double is an integer.
inline double trunc_non_negative(double x) {
  constexpr double kTwo52 = 4503599627370496.0;
  const double r = (x + kTwo52) - kTwo52, r_less = r - 1.0;  // both computed: selects, no branch
  const double floor = r > x ? r_less : r;
  return x < kTwo52 ? floor : x;
}

// The correlated field at pixel (u, v), as the plain code computes it.
inline double field_at(const Frame& f, int u, int v) {
  const int cell = f.cell;
  const int gx = u / cell, gy = v / cell;
  const double tx = (u - gx * cell + 0.5) / cell, ty = (v - gy * cell + 0.5) / cell;
  const float* g0 = &f.field_grid[size_t(gy) * f.grid_w + gx];
  const float* g1 = g0 + f.grid_w;
  const double w00 = (1 - tx) * (1 - ty), w10 = tx * (1 - ty), w01 = (1 - tx) * ty, w11 = tx * ty;
  return (w00 * g0[0] + w10 * g0[1] + w01 * g1[0] + w11 * g1[1]) /
         std::sqrt(w00 * w00 + w10 * w10 + w01 * w01 + w11 * w11);
}

// One pixel, the model's per-pixel code: occlusion -> edge artefacts -> disparity noise and quantization -> range
// -> dropout.
float pixel_plain(const Frame& f, int u, int v) {
  const int W = f.W, H = f.H;
  const size_t i = size_t(v) * W + u;
  const float z_true = f.truth[i];
  if (!(z_true > 0.0f) || (f.occluded && f.occluded[i])) return 0.0f;
  double z = z_true;
  if (f.edges) {
    float z_other = z_true, jump = 0.0f;
    auto consider = [&](int uu, int vv) {
      if (uu < 0 || vv < 0 || uu >= W || vv >= H) return;
      const float zn = f.truth[size_t(vv) * W + uu];
      if (zn > 0.0f && std::abs(zn - z_true) > jump) {
        jump = std::abs(zn - z_true);
        z_other = zn;
      }
    };
    consider(u - 1, v);
    consider(u + 1, v);
    consider(u, v - 1);
    consider(u, v + 1);
    if (jump > f.edge_jump && draw(f.key, i, kEdge) < f.edge_threshold) {
      if (uniform(f.key, i, kEdgeKind) < f.edge_invalid_fraction) return 0.0f;
      z += uniform(f.key, i, kEdgeBlend) * (double(z_other) - z);
    }
  }
  if (f.stereo) {
    const uint64_t normal_bits = draw(f.key, i >> 2, kGauss);
    const double white = double(f.normal[(normal_bits >> (16 * (i & 3))) & kNormalMask]);
    const double noise = f.correlated ? f.white_scale * white + f.field_scale * field_at(f, u, v) : white;
    double disparity = f.fb / z + f.subpixel * noise;
    if (f.step > 0.0 && disparity > 0.0 && disparity < 1e12)
      disparity = double(int64_t(disparity * f.inv_step + 0.5)) * f.step;
    z = disparity > 0.0 ? f.fb / disparity : 0.0;
  }
  if (!(z >= f.min_m && z <= f.max_m)) z = 0.0;
  if (f.dropout_threshold > 0 && draw(f.key, i, kDropout) < f.dropout_threshold) z = 0.0;
  return float(z);
}

// A neighbour's depth makes pixel z an edge candidate (the plain code's jump > edge_jump, as an "any": the running
// maximum exceeds edge_jump >= 0 exactly when one neighbour's jump does). A missing neighbour is passed as z
// itself, which never qualifies (0, or NaN for infinite z, is not above edge_jump; z <= 0 and NaN fail zn > 0).
inline int edge_from(float zn, float z, float edge_jump) { return int(zn > 0.0f) & int(std::abs(zn - z) > edge_jump); }

// After the edge artefacts, branch-free: disparity noise (term = subpixel * normal), quantization, range, dropout
// (drop_counter: the dropout draw's counter), as the plain code computes them; 0 where keep is false.
template <bool Stereo, bool Quantize, bool Dropout>
__attribute__((always_inline)) inline float finish(const Frame& f, double z, bool keep, double term,
                                                   uint64_t drop_counter) {
  if (Stereo) {
    double disparity = f.fb / z + term;
    if (Quantize) {
      const double q = trunc_non_negative(disparity * f.inv_step + 0.5) * f.step;
      disparity = ((disparity > 0.0) & (disparity < 1e12)) ? q : disparity;
    }
    const double z_noisy = f.fb / disparity;  // computed for every pixel, selected after: no branch
    z = disparity > 0.0 ? z_noisy : 0.0;
  }
  keep &= (z >= f.min_m) & (z <= f.max_m);
  if (Dropout) keep &= !(splitmix64_mix(drop_counter) < f.dropout_threshold);
  const float z_out = float(z);
  return keep ? z_out : 0.0f;
}

// The disparity noise term subpixel * normal of pixels [u0, u0 + n) of row v (i0: the first's index) into
// term_pad[off .. off + n), off = i0 & 3: one draw per four pixels of the image (16 bits each).
__attribute__((always_inline)) inline void disparity_terms(const Frame& f, int v, int u0, int n, uint64_t i0,
                                                           double* term_pad) {
  alignas(64) uint64_t group_bits[kChunk / 4 + 2];
  const int off = int(i0 & 3);
  const uint64_t g0 = i0 >> 2;
  const int groups = (off + n + 3) / 4;
  const uint64_t base = f.key + (g0 * kStreams + kGauss + 1) * kGolden;
  for (int k = 0; k < groups; ++k) group_bits[k] = splitmix64_mix(base + uint64_t(k) * (kStreams * kGolden));
  const float* normal = f.normal;
  if (!f.correlated) {
    const double s = f.subpixel;
    for (int k = 0; k < groups; ++k) {
      const uint64_t b = group_bits[k];
      term_pad[4 * k + 0] = s * double(normal[b & kNormalMask]);
      term_pad[4 * k + 1] = s * double(normal[(b >> 16) & kNormalMask]);
      term_pad[4 * k + 2] = s * double(normal[(b >> 32) & kNormalMask]);
      term_pad[4 * k + 3] = s * double(normal[(b >> 48) & kNormalMask]);
    }
  } else {
    for (int k = 0; k < groups; ++k) {
      const uint64_t b = group_bits[k];
      for (int r = 0; r < 4; ++r) term_pad[4 * k + r] = double(normal[(b >> (16 * r)) & kNormalMask]);
    }
    for (int j = 0; j < n; ++j)
      term_pad[off + j] = f.subpixel * (f.white_scale * term_pad[off + j] + f.field_scale * field_at(f, u0 + j, v));
  }
}

// Edge candidates of pixels [u0, u0 + n) (cur: the first; up, down: the rows around it, or the row itself at
// the image's edge): valid, visible pixels with a neighbour that jumps by more than edge_jump. candidate[] is
// zeroed past n up to a multiple of 8.
template <bool Occlusion>
__attribute__((always_inline)) inline void edge_candidates(const Frame& f, const float* cur, const float* up,
                                                           const float* down, const uint8_t* occluded, int u0, int n,
                                                           uint8_t* candidate) {
  const float jump = f.edge_jump;
  const int first = u0 == 0 ? 1 : 0, last = u0 + n == f.W ? n - 1 : n;  // interior: both row neighbours exist
  for (int j = first; j < last; ++j) {
    const float z = cur[j];
    candidate[j] = uint8_t(int(z > 0.0f) & (edge_from(cur[j - 1], z, jump) | edge_from(cur[j + 1], z, jump) |
                                            edge_from(up[j], z, jump) | edge_from(down[j], z, jump)));
  }
  for (int j : {0, n - 1}) {
    if (j >= first && j < last) continue;
    const float z = cur[j];
    const float left = u0 + j > 0 ? cur[j - 1] : z, right = u0 + j + 1 < f.W ? cur[j + 1] : z;
    candidate[j] = uint8_t(int(z > 0.0f) & (edge_from(left, z, jump) | edge_from(right, z, jump) |
                                            edge_from(up[j], z, jump) | edge_from(down[j], z, jump)));
  }
  if (Occlusion)
    for (int j = 0; j < n; ++j) candidate[j] &= uint8_t(occluded[j] == 0);
  for (int j = n; j < kChunk + 8 && j % 8 != 0; ++j) candidate[j] = 0;
}

// The candidates' positions (eight flags at a time, mostly all zero), then those whose edge draw passes
// (branch-free), into list[]; returns how many passed.
__attribute__((always_inline)) inline int affected_edges(const Frame& f, const uint8_t* candidate, int n, uint64_t i0,
                                                         int* list) {
  int count = 0;
  for (int j0 = 0; j0 < n; j0 += 8) {
    uint64_t flags;
    std::memcpy(&flags, candidate + j0, 8);
    for (; flags; flags &= flags - 1) list[count++] = j0 + __builtin_ctzll(flags) / 8;
  }
  int affected = 0;
  for (int c = 0; c < count; ++c) {
    const int j = list[c];
    list[affected] = j;
    affected += draw(f.key, i0 + uint64_t(j), kEdge) < f.edge_threshold;
  }
  return affected;
}

// Passes over pixels [u0, u0 + n) of row v (n <= kChunk); always inlined into each instruction set's copy.
template <bool Stereo, bool Quantize, bool Dropout, bool Occlusion>
__attribute__((always_inline)) inline void chunk(const Frame& f, int v, int u0, int n) {
  const size_t row = size_t(v) * f.W;
  const float* cur = f.truth + row + u0;
  float* out = f.out + row + u0;
  const uint8_t* occluded = Occlusion ? f.occluded + row + u0 : nullptr;
  const uint64_t i0 = row + uint64_t(u0);

  alignas(64) double term_pad[kChunk + 8];
  const double* term = term_pad + int(i0 & 3);
  if (Stereo) disparity_terms(f, v, u0, n, i0, term_pad);

  // Every pixel as if it were no edge: branch-free.
  const uint64_t drop_base = f.key + (i0 * kStreams + kDropout + 1) * kGolden, drop_stride = kStreams * kGolden;
  for (int j = 0; j < n; ++j) {
    const float z_true = cur[j];
    bool keep = z_true > 0.0f;
    if (Occlusion) keep &= occluded[j] == 0;
    out[j] = finish<Stereo, Quantize, Dropout>(f, double(z_true), keep, Stereo ? term[j] : 0.0,
                                               drop_base + uint64_t(j) * drop_stride);
  }
  if (!f.edges) return;

  const float* up = v > 0 ? cur - f.W : cur;
  const float* down = v + 1 < f.H ? cur + f.W : cur;
  alignas(64) uint8_t candidate[kChunk + 8];
  edge_candidates<Occlusion>(f, cur, up, down, occluded, u0, n, candidate);
  alignas(64) int list[kChunk];
  const int affected = affected_edges(f, candidate, n, i0, list);

  // Those vanish or fly (a depth between their own and the neighbour's of the largest jump, the first of equal
  // ones in the order left, right, up, down; a missing neighbour is the pixel itself, which never wins).
  for (int c = 0; c < affected; ++c) {
    const int j = list[c];
    const float z_true = cur[j];
    const float neighbours[4] = {cur[u0 + j > 0 ? j - 1 : j], cur[u0 + j + 1 < f.W ? j + 1 : j], up[j], down[j]};
    float z_other = z_true, largest = 0.0f;
    for (float zn : neighbours) {
      const float d = std::abs(zn - z_true);
      const bool wins = (zn > 0.0f) & (d > largest);
      largest = wins ? d : largest;
      z_other = wins ? zn : z_other;
    }
    const uint64_t i = i0 + uint64_t(j);
    const bool vanish = uniform(f.key, i, kEdgeKind) < f.edge_invalid_fraction;
    double z = z_true;
    z += uniform(f.key, i, kEdgeBlend) * (double(z_other) - z);
    out[j] =
        finish<Stereo, Quantize, Dropout>(f, z, !vanish, Stereo ? term[j] : 0.0, drop_base + uint64_t(j) * drop_stride);
  }
}

template <bool Stereo, bool Quantize, bool Dropout, bool Occlusion>
__attribute__((always_inline)) inline void row(const Frame& f, int v) {
  for (int u0 = 0; u0 < f.W; u0 += kChunk)
    chunk<Stereo, Quantize, Dropout, Occlusion>(f, v, u0, std::min(kChunk, f.W - u0));
}

// The variants of the row passes, for one instruction set.
__attribute__((always_inline)) inline void row_any(const Frame& f, int v) {
  const bool quantize = f.step > 0.0, dropout = f.dropout_threshold > 0, occlusion = f.occluded != nullptr;
  if (!f.stereo) {
    if (dropout) occlusion ? row<false, false, true, true>(f, v) : row<false, false, true, false>(f, v);
    else occlusion ? row<false, false, false, true>(f, v) : row<false, false, false, false>(f, v);
  } else if (quantize) {
    if (dropout) occlusion ? row<true, true, true, true>(f, v) : row<true, true, true, false>(f, v);
    else occlusion ? row<true, true, false, true>(f, v) : row<true, true, false, false>(f, v);
  } else {
    if (dropout) occlusion ? row<true, false, true, true>(f, v) : row<true, false, true, false>(f, v);
    else occlusion ? row<true, false, false, true>(f, v) : row<true, false, false, false>(f, v);
  }
}

void row_baseline(const Frame& f, int v) { row_any(f, v); }

#if defined(__x86_64__) || defined(__i386__)
#define STVL_NOISE_X86 1
#if defined(__clang__)
#define STVL_NOISE_AVX512 "avx512f,avx512dq,avx512vl,avx512bw"
#else
#define STVL_NOISE_AVX512 "avx512f,avx512dq,avx512vl,avx512bw,prefer-vector-width=512"
#endif
__attribute__((target("avx2"))) void row_avx2(const Frame& f, int v) { row_any(f, v); }
__attribute__((target(STVL_NOISE_AVX512))) void row_avx512(const Frame& f, int v) { row_any(f, v); }
#else
#define STVL_NOISE_X86 0
void row_avx2(const Frame& f, int v) { row_any(f, v); }
void row_avx512(const Frame& f, int v) { row_any(f, v); }
#endif

}  // namespace

Simd best_simd() {
#if STVL_NOISE_X86
  __builtin_cpu_init();  // the checks include the OS's support for the wider registers
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl") &&
      __builtin_cpu_supports("avx512bw"))
    return Simd::kAvx512;
  if (__builtin_cpu_supports("avx2")) return Simd::kAvx2;
#endif
  return Simd::kBaseline;
}

void noise_row(const Frame& f, int v, Simd simd) {
  // The vector passes truncate the quantized disparity without an int64 conversion, exact below 2^63: disparities
  // under 1e12 px stay there when the step is at least 1e-6 px. Smaller steps take the plain code.
  if (f.stereo && f.step > 0.0 && !(f.inv_step <= 1e6)) return noise_row_plain(f, v);
  switch (simd) {
    case Simd::kAvx512: return row_avx512(f, v);
    case Simd::kAvx2: return row_avx2(f, v);
    case Simd::kBaseline: return row_baseline(f, v);
  }
}

void noise_row_plain(const Frame& f, int v) {
  for (int u = 0; u < f.W; ++u) f.out[size_t(v) * f.W + u] = pixel_plain(f, u, v);
}

}  // namespace stvl::sensors::noise_rows

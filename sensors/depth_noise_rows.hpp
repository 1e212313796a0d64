#pragma once
// The noise model's row kernel (internal to sensors/: depth_noise.cpp drives it). One row at a time, in branch-free
// passes the compiler vectorizes (hash draws, disparity noise, quantization, range, dropouts), then the edge
// candidates, compacted, in passes of their own; compiled three times (x86-64 baseline, AVX2, AVX-512), all giving
// the plain per-pixel code's floats bit for bit.
#include <cstdint>

#include "sensors/depth_noise.hpp"

namespace stvl::sensors::noise_rows {

enum Stream : uint64_t { kGauss = 0, kEdge, kEdgeKind, kEdgeBlend, kDropout, kHoleCount, kHole, kStreams };

using Simd = NoiseSimd;

// Everything a row needs, fixed for the frame. Pointers: truth (the clean image, W x H), out (the noisy one),
// occluded (W x H, 1 = shadowed; null when stereo occlusion is off), field_grid (null when not correlated).
struct Frame {
  const float* truth = nullptr;
  float* out = nullptr;
  const uint8_t* occluded = nullptr;
  const float* field_grid = nullptr;
  const float* normal = nullptr;  // 4096 equiprobable bins of a standard normal
  int W = 0, H = 0;
  uint64_t key = 0;
  double fb = 0.0, step = 0.0, inv_step = 0.0, min_m = 0.0, max_m = 0.0, subpixel = 0.0;
  bool stereo = false;
  bool edges = false;  // edge_probability > 0
  float edge_jump = 0.0f;
  uint64_t edge_threshold = 0;
  double edge_invalid_fraction = 0.0;
  uint64_t dropout_threshold = 0;
  bool correlated = false;
  int cell = 1, grid_w = 0;
  double white_scale = 1.0, field_scale = 0.0;
};

// The widest instruction set this CPU runs (AVX-512 F/DQ/VL/BW, AVX2, or the baseline).
Simd best_simd();

// Writes row v of f.out from f.truth, with the kernel compiled for `simd` (which the CPU must run).
void noise_row(const Frame& f, int v, Simd simd);

// The same row pixel by pixel, the model's plain per-pixel code; noise_row falls back to it where the vector passes
// would not be exact (disparity steps below 1e-6 px).
void noise_row_plain(const Frame& f, int v);

}  // namespace stvl::sensors::noise_rows

#pragma once
// D435-like stereo depth noise, deterministic for (seed, frame_index): every random draw comes from a counter-based
// hash of (seed, frame_index, pixel or blob index, stream), so frames can be regenerated in any order.
#include "sensors/camera.hpp"
#include "sensors/depth_image.hpp"

#include <cstdint>
#include <vector>

namespace stvl::sensors {

struct DepthNoiseConfig {
  bool enabled = true;
  // Stereo: disparity d = f * b / z (px) gets Gaussian noise of std subpixel, which to first order is Intel's RMS
  // depth error sigma_z = z^2 * subpixel / (f * baseline).
  double baseline_m = 0.050;
  double subpixel = 0.08;  // px (RMS subpixel accuracy; D435 spec 0.08 to 0.1)
  // Disparity quantization step in px (D4 ASIC: 1/32); 0 = off. Adds step / sqrt(12) = 0.009 px in quadrature to
  // the noise (+0.6 % at the defaults); the RMS test measures it together with the Gaussian part.
  double disparity_step_px = 1.0 / 32.0;
  // Edge / flying pixels: a pixel whose 4-neighbourhood depth jumps by more than edge_jump_m is affected with
  // probability edge_probability; then it is invalidated with probability edge_invalid_fraction, else it takes a
  // depth uniformly between its own and the farthest/nearest neighbour's (a "flying pixel").
  double edge_jump_m = 0.10;
  double edge_probability = 0.5;
  double edge_invalid_fraction = 0.5;
  // Independent per-pixel dropouts (probability per pixel).
  double dropout_probability = 0.002;
  // Holes: mean number of disk-shaped blobs per frame (actual count: floor or ceil, randomly), radius uniform in
  // [1, hole_max_radius_px] px.
  double holes_per_frame = 2.0;
  double hole_max_radius_px = 4.0;
  // Stereo occlusion (the bench's, off by default): the D435's depth is the left imager's view, and a pixel has depth
  // only where the right imager, baseline_m to its right, sees the same point. With d = fx * baseline / z the
  // point's disparity (px), pixel u appears at column u - d in the right image; it is invalid when that column is
  // left of left_band_margin_px - 0.5 (the left-edge band; geometric width d, widened by the margin, which the real
  // D435 shows: 23 px at 1.7 m where d = 11.5 px) or when a nearer pixel to its right lands at the same column or
  // further left (the occlusion shadow on the left of a foreground edge), widened leftwards by shadow_margin_px
  // (real shadows are 3.7 px wider than their geometric width, median; simulated ones with margin 0 already 1.9 px,
  // from the edge artifacts and rounding).
  // Computed on the clean image, before the other artifacts. Margins measured with stvl-bench noise-stats on the
  // real D435 recording in ../shared/realdata (see docs/fidelity.md); the band's edge moves per row and frame by a
  // uniform draw in [-left_band_jitter_px, +left_band_jitter_px] (real: 21 to 25 px, 10th to 90th percentile).
  bool stereo_occlusion = false;
  double left_band_margin_px = 12.0;
  double left_band_jitter_px = 2.0;
  double shadow_margin_px = 2.0;
  // Correlated disparity error (the bench's, off at 0): this share of the disparity noise variance (subpixel^2) is a
  // smooth field instead of per-pixel white noise, so Intel's RMS formula still gives each pixel's total. The field is
  // a grid of normals every correlated_cell_px, bilinearly interpolated (renormalized to unit variance), new each
  // frame. The real D435 (stvl-bench noise-stats, docs/fidelity.md): the difference of two frames of a wall at
  // 1.7 m correlates 0.98 between neighbours, 0.87 / 0.63 / 0.20 at 4 / 8 / 16 px along a row and 0.75 / 0.35 / 0.02
  // down a column; a 12 px grid gives 0.81 / 0.52 / 0.05 (isotropic: the mean of the two), hence 0.95 and 12 px.
  double correlated_fraction = 0.0;
  double correlated_cell_px = 12.0;

  // Throws std::invalid_argument naming the first bad field (negative, non-finite, probabilities outside [0, 1]).
  void validate() const;
};

// Instruction sets of the noise model's row kernel (x86-64's SSE2, AVX2, AVX-512): all give the same image.
enum class NoiseSimd { kBaseline, kAvx2, kAvx512 };

class DepthNoise {
 public:
  // intrinsics give f (fx, px) and the valid range [min_range_m, max_range_m]; results outside it become 0.
  DepthNoise(const DepthNoiseConfig& config, const CameraIntrinsics& intrinsics);

  // In place; no allocation after the first call for a given image size. Identity when config.enabled is false.
  // Throws std::invalid_argument when the image size does not match the intrinsics.
  // Rows run in parallel (TBB); parallel = false runs them in one pass on this thread (the images are equal).
  void apply(DepthImage& image, uint64_t seed, uint64_t frame_index, bool parallel = true);
  // The same from `clean` into `noisy` (resized; a copy of clean when disabled), without the in-place call's copy
  // of the clean image. clean and noisy may be the same image.
  void apply(const DepthImage& clean, DepthImage& noisy, uint64_t seed, uint64_t frame_index, bool parallel = true);

  // Caps the row kernel's instruction set (default: the widest this CPU runs; a cap above that is lowered to it).
  void limit_simd(NoiseSimd widest);
  NoiseSimd simd() const { return simd_; }  // the instruction set in use

  // Intel's RMS depth error at depth z (m): z^2 * subpixel / (fx * baseline).
  double rms_error_m(double z_m) const;
  const DepthNoiseConfig& config() const { return config_; }

 private:
  void apply_rows(const float* truth_m, float* out_m, uint64_t seed, uint64_t frame_index, bool parallel);

  DepthNoiseConfig config_;
  CameraIntrinsics intrinsics_;
  NoiseSimd simd_;
  std::vector<float> truth_;       // in-place apply: the input image, read while the output is modified
  std::vector<uint8_t> occluded_;  // stereo_occlusion: 1 where the right imager cannot see the pixel
  std::vector<float> field_grid_;  // correlated_fraction: this frame's grid of normals
};

}  // namespace stvl::sensors

#include "sensors/depth_noise.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "common/splitmix.hpp"
#include "sensors/depth_noise_rows.hpp"

namespace stvl::sensors {
namespace {

constexpr double kTwoPi = 6.28318530717958647692;

using noise_rows::kGauss;
using noise_rows::kHole;
using noise_rows::kHoleCount;
using noise_rows::kStreams;
using noise_rows::Stream;

// Frame key, computed once per frame; draws then cost one mix each.
inline uint64_t frame_key(uint64_t seed, uint64_t frame_index) {
  return splitmix64_mix(splitmix64(seed) ^ (frame_index * 0xD1B54A32D192ED03ULL + 0x632BE59BD9B4E019ULL));
}

// splitmix64 over the counter (index, stream): one mix per draw (as in depth_noise_rows.cpp).
inline uint64_t draw(uint64_t key, uint64_t index, Stream stream) {
  return splitmix64_mix(key + (index * kStreams + stream + 1) * 0x9E3779B97F4A7C15ULL);
}

inline double uniform(uint64_t key, uint64_t index, Stream stream) {
  return double(draw(key, index, stream) >> 11) * 0x1.0p-53;  // [0, 1)
}

// Threshold for "draw < p" done on the raw 64-bit value.
inline uint64_t threshold(double p) { return p >= 1.0 ? ~0ULL : uint64_t(p * 18446744073709551616.0); }

// Standard normal quantized to 4096 equiprobable bins, each represented by its conditional mean: drawing a normal
// is one table look-up on 12 random bits (std 0.9999; far finer than the 1/32 px disparity step it feeds).
constexpr int kNormalBits = 12;
constexpr int kNormalBins = 1 << kNormalBits;

const std::array<float, kNormalBins>& normal_table() {
  static const std::array<float, kNormalBins> table = [] {
    auto cdf = [](double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); };
    auto pdf = [](double x) { return std::exp(-0.5 * x * x) / std::sqrt(kTwoPi); };
    auto quantile = [&](double p) {  // bisection is plenty for a one-off table
      double lo = -40.0, hi = 40.0;
      for (int i = 0; i < 100; ++i) (cdf(0.5 * (lo + hi)) < p ? lo : hi) = 0.5 * (lo + hi);
      return 0.5 * (lo + hi);
    };
    std::array<float, kNormalBins> t{};
    double lower_pdf = 0.0;  // pdf at the lower edge of bin k (0 at -infinity)
    for (int k = 0; k < kNormalBins; ++k) {
      const double upper_pdf = k + 1 < kNormalBins ? pdf(quantile(double(k + 1) / kNormalBins)) : 0.0;
      t[size_t(k)] = float(kNormalBins * (lower_pdf - upper_pdf));
      lower_pdf = upper_pdf;
    }
    return t;
  }();
  return table;
}

// One row of the stereo-occlusion mask (DepthNoiseConfig::stereo_occlusion), scanned right to left: x = u - d is
// the column where pixel u appears in the right image; a pixel is shadowed when a pixel to its right lands at or
// left of x (min_x), and the shadow is widened leftwards by shadow_margin_px pixels.
void occlusion_row(const float* z_m, uint8_t* occluded, int W, double fb, double band_margin_px, int shadow_margin_px) {
  double min_x = std::numeric_limits<double>::infinity();
  int extend = 0;
  for (int u = W - 1; u >= 0; --u) {
    occluded[u] = 0;
    if (!(z_m[u] > 0.0f)) {
      if (extend > 0) --extend;
      continue;
    }
    const double x = u - fb / double(z_m[u]);
    bool shadow = x >= min_x;
    if (shadow) {
      extend = shadow_margin_px;
    } else if (extend > 0) {
      shadow = true;
      --extend;
    }
    occluded[u] = shadow || x < band_margin_px - 0.5;
    min_x = std::min(min_x, x);
  }
}

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("DepthNoiseConfig: " + message);
}

void require_probability(double p, const char* name) {
  require(std::isfinite(p) && p >= 0.0 && p <= 1.0, std::string(name) + " " + std::to_string(p) + " not in [0, 1]");
}

void require_non_negative(double x, const char* name) {
  require(std::isfinite(x) && x >= 0.0, std::string(name) + " " + std::to_string(x) + " must be finite and >= 0");
}

}  // namespace

void DepthNoiseConfig::validate() const {
  require(std::isfinite(baseline_m) && baseline_m > 0.0, "baseline_m " + std::to_string(baseline_m) + " must be > 0");
  require_non_negative(subpixel, "subpixel");
  require_non_negative(disparity_step_px, "disparity_step_px");
  require_non_negative(edge_jump_m, "edge_jump_m");
  require_probability(edge_probability, "edge_probability");
  require_probability(edge_invalid_fraction, "edge_invalid_fraction");
  require_probability(dropout_probability, "dropout_probability");
  require_non_negative(holes_per_frame, "holes_per_frame");
  require(holes_per_frame <= 1e4, "holes_per_frame " + std::to_string(holes_per_frame) + " above 10000");
  require(std::isfinite(hole_max_radius_px) && hole_max_radius_px >= 1.0 && hole_max_radius_px <= 1e3,
          "hole_max_radius_px " + std::to_string(hole_max_radius_px) + " not in [1, 1000]");
  require_non_negative(left_band_margin_px, "left_band_margin_px");
  require_non_negative(left_band_jitter_px, "left_band_jitter_px");
  require_non_negative(shadow_margin_px, "shadow_margin_px");
  require(std::isfinite(correlated_fraction) && correlated_fraction >= 0.0 && correlated_fraction <= 1.0,
          "correlated_fraction " + std::to_string(correlated_fraction) + " not in [0, 1]");
  require(std::isfinite(correlated_cell_px) && correlated_cell_px >= 1.0 && correlated_cell_px <= 1e3,
          "correlated_cell_px " + std::to_string(correlated_cell_px) + " not in [1, 1000]");
  require(left_band_margin_px <= 1e4 && left_band_jitter_px <= 1e4 && shadow_margin_px <= 1e4,
          "left_band_margin_px, left_band_jitter_px and shadow_margin_px must be <= 10000");
}

DepthNoise::DepthNoise(const DepthNoiseConfig& config, const CameraIntrinsics& intrinsics)
    : config_(config), intrinsics_(intrinsics), simd_(noise_rows::best_simd()) {
  config_.validate();
  intrinsics_.validate();
}

double DepthNoise::rms_error_m(double z_m) const {
  return z_m * z_m * config_.subpixel / (intrinsics_.fx * config_.baseline_m);
}

void DepthNoise::limit_simd(NoiseSimd widest) { simd_ = std::min(widest, noise_rows::best_simd()); }

namespace {

void require_size(const DepthImage& image, const CameraIntrinsics& k) {
  if (image.width != k.width || image.height != k.height || image.depth_m.size() != size_t(k.width) * k.height) {
    throw std::invalid_argument("DepthNoise::apply: image " + std::to_string(image.width) + "x" +
                                std::to_string(image.height) + " does not match intrinsics " + std::to_string(k.width) +
                                "x" + std::to_string(k.height));
  }
}

}  // namespace

void DepthNoise::apply(DepthImage& image, uint64_t seed, uint64_t frame_index, bool parallel) {
  if (!config_.enabled) return;
  require_size(image, intrinsics_);
  truth_.assign(image.depth_m.begin(), image.depth_m.end());
  apply_rows(truth_.data(), image.depth_m.data(), seed, frame_index, parallel);
}

void DepthNoise::apply(const DepthImage& clean, DepthImage& noisy, uint64_t seed, uint64_t frame_index, bool parallel) {
  if (&clean == &noisy) return apply(noisy, seed, frame_index, parallel);
  require_size(clean, intrinsics_);
  noisy.width = clean.width;
  noisy.height = clean.height;
  if (!config_.enabled) {
    noisy.depth_m = clean.depth_m;
    return;
  }
  noisy.depth_m.resize(clean.depth_m.size());
  apply_rows(clean.depth_m.data(), noisy.depth_m.data(), seed, frame_index, parallel);
}

namespace {

// The frame's per-pixel noise settings (noise_rows::Frame) from the config and intrinsics; the occlusion mask and
// the correlated field's grid are apply_rows()'s to add.
noise_rows::Frame noise_frame(const DepthNoiseConfig& config, const CameraIntrinsics& k, const float* truth_m,
                              float* out_m, uint64_t key) {
  noise_rows::Frame f;
  f.truth = truth_m;
  f.out = out_m;
  f.normal = normal_table().data();
  f.W = k.width;
  f.H = k.height;
  f.key = key;
  f.fb = k.fx * config.baseline_m;  // px * m
  f.step = config.disparity_step_px;
  f.inv_step = f.step > 0.0 ? 1.0 / f.step : 0.0;
  f.min_m = k.min_range_m;
  f.max_m = k.max_range_m;
  f.subpixel = config.subpixel;
  f.stereo = config.subpixel > 0.0 || f.step > 0.0;
  f.edges = config.edge_probability > 0.0;
  f.edge_jump = float(config.edge_jump_m);
  f.edge_threshold = threshold(config.edge_probability);
  f.edge_invalid_fraction = config.edge_invalid_fraction;
  f.dropout_threshold = threshold(config.dropout_probability);
  // Correlated disparity error: a grid of normals every cell px (one beyond each edge), bilinearly interpolated and
  // renormalized to unit variance per pixel; drawn from a key of its own.
  f.correlated = config.correlated_fraction > 0.0 && config.subpixel > 0.0;
  f.cell = std::max(1, int(std::lround(config.correlated_cell_px)));
  f.grid_w = f.W / f.cell + 2;
  f.white_scale = std::sqrt(1.0 - config.correlated_fraction);
  f.field_scale = std::sqrt(config.correlated_fraction);
  return f;
}

// The correlated field's grid of normals (grid_w x grid_h) for the frame `key`.
void draw_field_grid(uint64_t key, std::size_t cells, std::vector<float>& grid) {
  const uint64_t field_key = splitmix64_mix(key ^ 0xC2B2AE3D27D4EB4FULL);
  grid.resize(cells);
  for (size_t j = 0; j < grid.size(); ++j) grid[j] = normal_table()[draw(field_key, j, kGauss) & (kNormalBins - 1)];
}

// holes_per_frame round holes (a fractional count: one more with that probability) of radius 1..hole_max_radius_px
// at uniform positions, zeroed in out_m.
void punch_holes(const DepthNoiseConfig& config, uint64_t key, int W, int H, float* out_m) {
  const double whole = std::floor(config.holes_per_frame);
  const int holes = int(whole) + (uniform(key, 0, kHoleCount) < config.holes_per_frame - whole ? 1 : 0);
  for (int h = 0; h < holes; ++h) {
    const double hole_u = uniform(key, 3 * uint64_t(h), kHole) * W;
    const double hole_v = uniform(key, 3 * uint64_t(h) + 1, kHole) * H;
    const double radius = 1.0 + uniform(key, 3 * uint64_t(h) + 2, kHole) * (config.hole_max_radius_px - 1.0);
    const int u0 = std::max(0, int(std::floor(hole_u - radius))), u1 = std::min(W - 1, int(std::ceil(hole_u + radius)));
    const int v0 = std::max(0, int(std::floor(hole_v - radius))), v1 = std::min(H - 1, int(std::ceil(hole_v + radius)));
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        if ((u - hole_u) * (u - hole_u) + (v - hole_v) * (v - hole_v) <= radius * radius) {
          out_m[size_t(v) * W + u] = 0.0f;
        }
      }
    }
  }
}

}  // namespace

void DepthNoise::apply_rows(const float* truth_m, float* out_m, uint64_t seed, uint64_t frame_index, bool parallel) {
  const int W = intrinsics_.width, H = intrinsics_.height;
  const uint64_t key = frame_key(seed, frame_index);
  noise_rows::Frame f = noise_frame(config_, intrinsics_, truth_m, out_m, key);
  const bool occlusion = config_.stereo_occlusion;
  if (occlusion) occluded_.resize(size_t(W) * H);
  f.occluded = occlusion ? occluded_.data() : nullptr;
  const uint64_t band_key = splitmix64_mix(key ^ 0x5BD1E9955BD1E995ULL);  // own draws: the others stay as they were
  const int shadow_margin = int(std::lround(config_.shadow_margin_px));
  if (f.correlated) {
    const int grid_h = H / f.cell + 2;
    draw_field_grid(key, size_t(f.grid_w) * grid_h, field_grid_);
    f.field_grid = field_grid_.data();
  }

  // Every pixel is a function of the frame key, its index and the clean image, so rows run in parallel (TBB)
  // and give the same image as one thread does.
  const NoiseSimd simd = simd_;
  const auto noise_rows = [&](const tbb::blocked_range<int>& rows) {
    for (int v = rows.begin(); v < rows.end(); ++v) {
      if (occlusion) {
        const double band = config_.left_band_margin_px +
                            config_.left_band_jitter_px * (2.0 * uniform(band_key, uint64_t(v), kGauss) - 1.0);
        occlusion_row(truth_m + size_t(v) * W, &occluded_[size_t(v) * W], W, f.fb, band, shadow_margin);
      }
      noise_rows::noise_row(f, v, simd);
    }
  };
  if (parallel) tbb::parallel_for(tbb::blocked_range<int>(0, H, 8), noise_rows);
  else noise_rows(tbb::blocked_range<int>(0, H));
  punch_holes(config_, key, W, H, out_m);
}

}  // namespace stvl::sensors

#include "sensors/reference/depth_noise.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "common/splitmix.hpp"

namespace stvl::sensors::reference {
namespace {

constexpr double kTwoPi = 6.28318530717958647692;

enum Stream : uint64_t { kGauss = 0, kEdge, kEdgeKind, kEdgeBlend, kDropout, kHoleCount, kHole, kStreams };

// Frame key, computed once per frame; draws then cost one mix each.
inline uint64_t frame_key(uint64_t seed, uint64_t frame_index) {
  return splitmix64_mix(splitmix64(seed) ^ (frame_index * 0xD1B54A32D192ED03ULL + 0x632BE59BD9B4E019ULL));
}

// splitmix64 over the counter (index, stream): one mix per draw.
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

}  // namespace

DepthNoise::DepthNoise(const DepthNoiseConfig& config, const CameraIntrinsics& intrinsics)
    : config_(config), intrinsics_(intrinsics) {
  config_.validate();
  intrinsics_.validate();
}

void DepthNoise::apply(DepthImage& image, uint64_t seed, uint64_t frame_index, bool parallel) {
  if (!config_.enabled) return;
  const int W = intrinsics_.width, H = intrinsics_.height;
  if (image.width != W || image.height != H || image.depth_m.size() != size_t(W) * H) {
    throw std::invalid_argument("DepthNoise::apply: image " + std::to_string(image.width) + "x" +
                                std::to_string(image.height) + " does not match intrinsics " + std::to_string(W) + "x" +
                                std::to_string(H));
  }
  truth_.assign(image.depth_m.begin(), image.depth_m.end());
  const uint64_t key = frame_key(seed, frame_index);
  const double fb = intrinsics_.fx * config_.baseline_m;  // px * m
  const double step = config_.disparity_step_px;
  const double inv_step = step > 0.0 ? 1.0 / step : 0.0;
  const double min_m = intrinsics_.min_range_m, max_m = intrinsics_.max_range_m;
  const float edge_jump = float(config_.edge_jump_m);
  const bool stereo = config_.subpixel > 0.0 || step > 0.0;
  const uint64_t edge_threshold = threshold(config_.edge_probability);
  const uint64_t dropout_threshold = threshold(config_.dropout_probability);

  const bool occlusion = config_.stereo_occlusion;
  if (occlusion) occluded_.resize(truth_.size());
  const uint64_t band_key = splitmix64_mix(key ^ 0x5BD1E9955BD1E995ULL);  // own draws: the others stay as they were
  const int shadow_margin = int(std::lround(config_.shadow_margin_px));
  // Correlated disparity error: a grid of normals every cell px (one beyond each edge), bilinearly interpolated and
  // renormalized to unit variance per pixel; drawn from a key of its own.
  const bool correlated = config_.correlated_fraction > 0.0 && config_.subpixel > 0.0;
  const int cell = std::max(1, int(std::lround(config_.correlated_cell_px)));
  const int grid_w = W / cell + 2, grid_h = H / cell + 2;
  const double white_scale = std::sqrt(1.0 - config_.correlated_fraction);
  const double field_scale = std::sqrt(config_.correlated_fraction);
  if (correlated) {
    const uint64_t field_key = splitmix64_mix(key ^ 0xC2B2AE3D27D4EB4FULL);
    field_grid_.resize(size_t(grid_w) * grid_h);
    for (size_t j = 0; j < field_grid_.size(); ++j)
      field_grid_[j] = normal_table()[draw(field_key, j, kGauss) & (kNormalBins - 1)];
  }

  const std::array<float, kNormalBins>& normal = normal_table();
  // Every pixel is a function of the frame key, its index and the clean image, so rows run in parallel (TBB)
  // and give the same image as one thread does.
  const auto noise_rows = [&](const tbb::blocked_range<int>& rows) {
    uint64_t normal_bits = 0;  // four 16-bit fields per draw, 12 bits used each: those of pixel group i / 4
    for (int v = rows.begin(); v < rows.end(); ++v) {
      if (occlusion) {
        const double band = config_.left_band_margin_px +
                            config_.left_band_jitter_px * (2.0 * uniform(band_key, uint64_t(v), kGauss) - 1.0);
        occlusion_row(&truth_[size_t(v) * W], &occluded_[size_t(v) * W], W, fb, band, shadow_margin);
      }
      for (int u = 0; u < W; ++u) {
        const size_t i = size_t(v) * W + u;
        if ((i & 3) == 0 || u == 0) normal_bits = draw(key, i >> 2, kGauss);
        const float z_true = truth_[i];
        if (!(z_true > 0.0f) || (occlusion && occluded_[i])) {
          image.depth_m[i] = 0.0f;
          continue;
        }
        double z = z_true;

        if (config_.edge_probability > 0.0) {
          float z_other = z_true, jump = 0.0f;
          auto consider = [&](int uu, int vv) {
            if (uu < 0 || vv < 0 || uu >= W || vv >= H) return;
            const float zn = truth_[size_t(vv) * W + uu];
            if (zn > 0.0f && std::abs(zn - z_true) > jump) {
              jump = std::abs(zn - z_true);
              z_other = zn;
            }
          };
          consider(u - 1, v);
          consider(u + 1, v);
          consider(u, v - 1);
          consider(u, v + 1);
          if (jump > edge_jump && draw(key, i, kEdge) < edge_threshold) {
            if (uniform(key, i, kEdgeKind) < config_.edge_invalid_fraction) {
              image.depth_m[i] = 0.0f;
              continue;
            }
            z += uniform(key, i, kEdgeBlend) * (double(z_other) - z);
          }
        }

        if (stereo && correlated) {
          const double white = double(normal[(normal_bits >> (16 * (i & 3))) & (kNormalBins - 1)]);
          const int gx = u / cell, gy = v / cell;
          const double tx = (u - gx * cell + 0.5) / cell, ty = (v - gy * cell + 0.5) / cell;
          const float* g0 = &field_grid_[size_t(gy) * grid_w + gx];
          const float* g1 = g0 + grid_w;
          const double w00 = (1 - tx) * (1 - ty), w10 = tx * (1 - ty), w01 = (1 - tx) * ty, w11 = tx * ty;
          const double field = (w00 * g0[0] + w10 * g0[1] + w01 * g1[0] + w11 * g1[1]) /
                               std::sqrt(w00 * w00 + w10 * w10 + w01 * w01 + w11 * w11);
          double disparity = fb / z + config_.subpixel * (white_scale * white + field_scale * field);
          if (step > 0.0 && disparity > 0.0 && disparity < 1e12)
            disparity = double(int64_t(disparity * inv_step + 0.5)) * step;
          z = disparity > 0.0 ? fb / disparity : 0.0;
        } else if (stereo) {
          double disparity =
              fb / z + config_.subpixel * double(normal[(normal_bits >> (16 * (i & 3))) & (kNormalBins - 1)]);
          if (step > 0.0 && disparity > 0.0 && disparity < 1e12)
            disparity = double(int64_t(disparity * inv_step + 0.5)) * step;
          z = disparity > 0.0 ? fb / disparity : 0.0;
        }
        if (!(z >= min_m && z <= max_m)) z = 0.0;
        if (dropout_threshold > 0 && draw(key, i, kDropout) < dropout_threshold) z = 0.0;
        image.depth_m[i] = float(z);
      }
    }
  };
  if (parallel) tbb::parallel_for(tbb::blocked_range<int>(0, H, 8), noise_rows);
  else noise_rows(tbb::blocked_range<int>(0, H));
  const double whole = std::floor(config_.holes_per_frame);
  const int holes = int(whole) + (uniform(key, 0, kHoleCount) < config_.holes_per_frame - whole ? 1 : 0);
  for (int h = 0; h < holes; ++h) {
    const double hole_u = uniform(key, 3 * uint64_t(h), kHole) * W;
    const double hole_v = uniform(key, 3 * uint64_t(h) + 1, kHole) * H;
    const double radius = 1.0 + uniform(key, 3 * uint64_t(h) + 2, kHole) * (config_.hole_max_radius_px - 1.0);
    const int u0 = std::max(0, int(std::floor(hole_u - radius))), u1 = std::min(W - 1, int(std::ceil(hole_u + radius)));
    const int v0 = std::max(0, int(std::floor(hole_v - radius))), v1 = std::min(H - 1, int(std::ceil(hole_v + radius)));
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        if ((u - hole_u) * (u - hole_u) + (v - hole_v) * (v - hole_v) <= radius * radius) {
          image.depth_m[size_t(v) * W + u] = 0.0f;
        }
      }
    }
  }
}

}  // namespace stvl::sensors::reference

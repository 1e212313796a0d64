#include "sensors/depth_stats.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "common/statistics.hpp"

namespace stvl::sensors {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool valid(float z) { return z > 0.0f && std::isfinite(z); }

// Index of the bin containing z, or -1.
int bin_of(double z_m, const std::vector<double>& centres_m, double half_width_m) {
  for (size_t k = 0; k < centres_m.size(); ++k)
    if (z_m >= centres_m[k] - half_width_m && z_m < centres_m[k] + half_width_m) return int(k);
  return -1;
}

}  // namespace

double invalid_fraction(const DepthImage& image) {
  if (image.depth_m.empty()) return kNaN;
  long invalid = 0;
  for (float z : image.depth_m) invalid += !valid(z);
  return double(invalid) / double(image.depth_m.size());
}

EdgeBandsPx invalid_edge_bands_px(const DepthImage& image) {
  const int W = image.width, H = image.height;
  std::vector<double> left, right, top, bottom;
  for (int v = 0; v < H; ++v) {
    int l = 0, r = 0;
    while (l < W && !valid(image.at(l, v))) ++l;
    while (r < W && !valid(image.at(W - 1 - r, v))) ++r;
    left.push_back(l);
    right.push_back(r);
  }
  for (int u = 0; u < W; ++u) {
    int t = 0, b = 0;
    while (t < H && !valid(image.at(u, t))) ++t;
    while (b < H && !valid(image.at(u, H - 1 - b))) ++b;
    top.push_back(t);
    bottom.push_back(b);
  }
  EdgeBandsPx bands;
  if (H > 0 && W > 0) {
    bands.left_px = median(left);
    bands.right_px = median(right);
    bands.top_px = median(top);
    bands.bottom_px = median(bottom);
  }
  return bands;
}

double left_band_geometric_px(const DepthImage& image, double fx_px, double baseline_m) {
  std::vector<double> widths;
  for (int v = 0; v < image.height; ++v) {
    for (int u = 0; u < image.width; ++u) {
      if (valid(image.at(u, v))) {
        widths.push_back(fx_px * baseline_m / image.at(u, v));
        break;
      }
    }
  }
  return median(widths);
}

DiscontinuityHoles discontinuity_holes(const DepthImage& image, double min_jump_m, double fx_px, double baseline_m) {
  const int W = image.width, H = image.height;
  DiscontinuityHoles out;
  long invalid_inner = 0;
  std::vector<double> run_px, geometric_px;
  for (int v = 0; v < H; ++v) {
    int first = 0, last = W - 1;
    while (first < W && !valid(image.at(first, v))) ++first;
    while (last >= 0 && !valid(image.at(last, v))) --last;
    for (int u = first; u <= last;) {
      if (valid(image.at(u, v))) {
        ++u;
        continue;
      }
      const int s = u;
      while (u <= last && !valid(image.at(u, v))) ++u;
      const long length = u - s;
      invalid_inner += length;
      const double z_left = image.at(s - 1, v), z_right = image.at(u, v);  // both valid: s > first, u <= last
      if (std::abs(z_left - z_right) <= min_jump_m) continue;
      ++out.runs;
      out.invalid_px += length;
      if (z_left > z_right) {
        out.far_left_px += length;
        run_px.push_back(double(length));
        geometric_px.push_back(fx_px * baseline_m * (1.0 / z_right - 1.0 / z_left));
      } else {
        out.far_right_px += length;
      }
    }
  }
  out.fraction_of_invalid = invalid_inner > 0 ? double(out.invalid_px) / double(invalid_inner) : 0.0;
  out.median_run_px = run_px.empty() ? 0.0 : median(run_px);
  out.median_geometric_px = geometric_px.empty() ? 0.0 : median(geometric_px);
  return out;
}

std::vector<DepthBinStat> temporal_sigma_m(const DepthImage& a, const DepthImage& b,
                                           const std::vector<double>& centres_m, double half_width_m, long min_samples,
                                           double sigma_at_1m_m) {
  if (a.width != b.width || a.height != b.height || a.depth_m.size() != b.depth_m.size())
    throw std::invalid_argument("temporal_sigma_m: frames of different sizes");
  std::vector<std::vector<double>> diffs(centres_m.size()), normalized(centres_m.size());
  std::vector<double> depth_sum(centres_m.size(), 0.0);
  for (size_t i = 0; i < a.depth_m.size(); ++i) {
    if (!valid(a.depth_m[i]) || !valid(b.depth_m[i])) continue;
    const double z = 0.5 * (double(a.depth_m[i]) + b.depth_m[i]);
    const int k = bin_of(z, centres_m, half_width_m);
    if (k < 0) continue;
    diffs[size_t(k)].push_back(double(a.depth_m[i]) - b.depth_m[i]);
    if (sigma_at_1m_m > 0.0) normalized[size_t(k)].push_back(diffs[size_t(k)].back() / (sigma_at_1m_m * z * z));
    depth_sum[size_t(k)] += z;
  }
  std::vector<DepthBinStat> out;
  for (size_t k = 0; k < centres_m.size(); ++k) {
    DepthBinStat s;
    s.centre_m = centres_m[k];
    s.samples = long(diffs[k].size());
    s.mean_depth_m = s.samples > 0 ? depth_sum[k] / double(s.samples) : kNaN;
    s.value_m = s.ratio_to_z2_law = kNaN;
    // RMS of the differences within 4 MAD-sigmas of their median, / sqrt(2). The MAD alone is biased on quantized
    // depth (its median lands on the grid): on the simulated D435 (1/32 px disparity steps) 1.4826 MAD / sqrt(2)
    // reads 0.82 of the noise's known sigma, this 1.00; real depth is quantized too (1/32 px, then 1 mm units).
    const auto robust_sigma = [](std::vector<double> values, double* mad_sigma) {
      const double m = median(values);
      std::vector<double> deviations(values.size());
      for (size_t i = 0; i < values.size(); ++i) deviations[i] = std::abs(values[i] - m);
      const double sigma_mad = 1.4826 * median(deviations);
      if (mad_sigma) *mad_sigma = sigma_mad / std::sqrt(2.0);
      double sum_sq = 0.0;
      long kept = 0;
      for (double d : values)
        if (std::abs(d - m) <= 4.0 * sigma_mad) {
          sum_sq += (d - m) * (d - m);
          ++kept;
        }
      return kept > 0 ? std::sqrt(sum_sq / double(kept)) / std::sqrt(2.0) : kNaN;
    };
    s.mad_sigma_m = kNaN;
    if (s.samples >= min_samples && s.samples > 0) {
      s.value_m = robust_sigma(diffs[k], &s.mad_sigma_m);
      if (sigma_at_1m_m > 0.0) s.ratio_to_z2_law = robust_sigma(normalized[k], nullptr);
    }
    out.push_back(s);
  }
  return out;
}

namespace {

// The mean depth of the patch_px x patch_px patch at (u0, v0) when every pixel has depth and the depths span at
// most max_range_fraction of the mean (a flat patch); nullopt otherwise.
std::optional<double> flat_patch_mean(const DepthImage& image, int u0, int v0, int patch_px,
                                      double max_range_fraction) {
  double lo = std::numeric_limits<double>::infinity(), hi = 0.0, sum = 0.0;
  for (int v = v0; v < v0 + patch_px; ++v)
    for (int u = u0; u < u0 + patch_px; ++u) {
      const float z = image.at(u, v);
      if (!valid(z)) return std::nullopt;
      lo = std::min(lo, double(z));
      hi = std::max(hi, double(z));
      sum += z;
    }
  const double mean = sum / (patch_px * patch_px);
  if (hi - lo > max_range_fraction * mean) return std::nullopt;
  return mean;
}

// RMS of the depth residuals of the patch against the least-squares plane in inverse depth (a plane in 3D is
// linear in 1/z over the pixels).
double plane_fit_residual_rms(const DepthImage& image, int u0, int v0, int patch_px) {
  const double c = 0.5 * (patch_px - 1);  // patch-centred coordinates keep the normal equations well conditioned
  Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
  Eigen::Vector3d Atb = Eigen::Vector3d::Zero();
  for (int v = v0; v < v0 + patch_px; ++v)
    for (int u = u0; u < u0 + patch_px; ++u) {
      const Eigen::Vector3d row(u - u0 - c, v - v0 - c, 1.0);
      AtA += row * row.transpose();
      Atb += row / double(image.at(u, v));
    }
  const Eigen::Vector3d p = AtA.ldlt().solve(Atb);
  double sq = 0.0;
  for (int v = v0; v < v0 + patch_px; ++v)
    for (int u = u0; u < u0 + patch_px; ++u) {
      const double w = p.x() * (u - u0 - c) + p.y() * (v - v0 - c) + p.z();
      const double r = double(image.at(u, v)) - 1.0 / w;
      sq += r * r;
    }
  return std::sqrt(sq / (patch_px * patch_px));
}

}  // namespace

std::vector<DepthBinStat> plane_fit_rms_m(const DepthImage& image, const std::vector<double>& centres_m,
                                          double half_width_m, int patch_px, double max_range_fraction,
                                          long min_samples, double sigma_at_1m_m) {
  if (patch_px < 3) throw std::invalid_argument("plane_fit_rms_m: patch_px must be >= 3");
  std::vector<std::vector<double>> rms(centres_m.size()), normalized(centres_m.size());
  std::vector<double> depth_sum(centres_m.size(), 0.0);
  for (int v0 = 0; v0 + patch_px <= image.height; v0 += patch_px) {
    for (int u0 = 0; u0 + patch_px <= image.width; u0 += patch_px) {
      const std::optional<double> flat_mean = flat_patch_mean(image, u0, v0, patch_px, max_range_fraction);
      if (!flat_mean) continue;
      const double mean = *flat_mean;
      const int k = bin_of(mean, centres_m, half_width_m);
      if (k < 0) continue;
      rms[size_t(k)].push_back(plane_fit_residual_rms(image, u0, v0, patch_px));
      depth_sum[size_t(k)] += mean;
      if (sigma_at_1m_m > 0.0) normalized[size_t(k)].push_back(rms[size_t(k)].back() / (sigma_at_1m_m * mean * mean));
    }
  }
  std::vector<DepthBinStat> out;
  for (size_t k = 0; k < centres_m.size(); ++k) {
    DepthBinStat s;
    s.centre_m = centres_m[k];
    s.samples = long(rms[k].size());
    s.mean_depth_m = s.samples > 0 ? depth_sum[k] / double(s.samples) : kNaN;
    s.mad_sigma_m = kNaN;
    const bool enough = s.samples >= min_samples && s.samples > 0;
    s.value_m = enough ? median(rms[k]) : kNaN;
    s.ratio_to_z2_law = enough && sigma_at_1m_m > 0.0 ? median(normalized[k]) : kNaN;
    out.push_back(s);
  }
  return out;
}

}  // namespace stvl::sensors

#include "analysis/noise_stats.hpp"

#include <cmath>
#include <cstdio>
#include <functional>
#include <stdexcept>

#include "common/units.hpp"

namespace stvl::analysis {
namespace {

nlohmann::json number(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

std::string cell(double x, const char* format) {
  if (!std::isfinite(x)) return "-";
  char text[32];
  std::snprintf(text, sizeof text, format, x);
  return text;
}

nlohmann::json bins(const std::vector<sensors::DepthBinStat>& stats, double fx_px, const NoiseStatsOptions& options) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& b : stats) {
    // ratio_to_intel: each sample against Intel's formula at its own depth (a bin mixes depths: a wall at 1.7 m
    // sits in the 1.5 m bin); intel_rms_m: the formula at the samples' mean depth.
    out.push_back({{"centre_m", b.centre_m},
                   {"samples", b.samples},
                   {"mean_depth_m", number(b.mean_depth_m)},
                   {"value_m", number(b.value_m)},
                   {"mad_sigma_m", number(b.mad_sigma_m)},
                   {"intel_rms_m", number(intel_rms_m(b.mean_depth_m, fx_px, options))},
                   {"ratio_to_intel", number(b.ratio_to_z2_law)}});
  }
  return out;
}

}  // namespace

double intel_rms_m(double z_m, double fx_px, const NoiseStatsOptions& options) {
  return z_m * z_m * options.subpixel / (fx_px * options.baseline_m);
}

NoiseStats compute_noise_stats(const sensors::DepthImage& first, const sensors::DepthImage& second,
                               const sensors::CameraIntrinsics& intrinsics, const NoiseStatsOptions& options) {
  for (const sensors::DepthImage* image : {&first, &second}) {
    if (image->width != intrinsics.width || image->height != intrinsics.height ||
        image->depth_m.size() != size_t(image->width) * size_t(image->height))
      throw std::invalid_argument("noise-stats: a " + std::to_string(image->width) + "x" +
                                  std::to_string(image->height) + " frame does not match the intrinsics' " +
                                  std::to_string(intrinsics.width) + "x" + std::to_string(intrinsics.height));
  }
  NoiseStats s;
  s.invalid_fraction = sensors::invalid_fraction(first);
  s.bands = sensors::invalid_edge_bands_px(first);
  s.left_band_geometric_px = sensors::left_band_geometric_px(first, intrinsics.fx, options.baseline_m);
  s.holes = sensors::discontinuity_holes(first, options.min_jump_m, intrinsics.fx, options.baseline_m);
  const double intel_at_1m_m = intel_rms_m(1.0, intrinsics.fx, options);
  s.plane_fit_rms =
      sensors::plane_fit_rms_m(first, options.bin_centres_m, options.bin_half_width_m, 12, 0.25, 5, intel_at_1m_m);
  s.temporal_sigma =
      sensors::temporal_sigma_m(first, second, options.bin_centres_m, options.bin_half_width_m, 100, intel_at_1m_m);
  return s;
}

nlohmann::json to_json(const NoiseStats& s, double fx_px, const NoiseStatsOptions& options) {
  const auto& h = s.holes;
  return {{"invalid_fraction", s.invalid_fraction},
          {"edge_bands_px",
           {{"left", s.bands.left_px},
            {"right", s.bands.right_px},
            {"top", s.bands.top_px},
            {"bottom", s.bands.bottom_px}}},
          {"left_band_geometric_px", number(s.left_band_geometric_px)},
          {"discontinuity_holes",
           {{"runs", h.runs},
            {"invalid_px", h.invalid_px},
            {"fraction_of_invalid", h.fraction_of_invalid},
            {"far_left_px", h.far_left_px},
            {"far_right_px", h.far_right_px},
            {"far_left_share", number(double(h.far_left_px) / double(h.far_left_px + h.far_right_px))},
            {"median_run_px", h.median_run_px},
            {"median_geometric_px", h.median_geometric_px}}},
          {"plane_fit_rms", bins(s.plane_fit_rms, fx_px, options)},
          {"temporal_sigma", bins(s.temporal_sigma, fx_px, options)}};
}

namespace {

// "| figure | a | b | Intel formula |" and its separator line.
std::string noise_table_header(const std::vector<std::string>& names) {
  std::string out = "| figure |";
  for (const auto& n : names) out += " " + n + " |";
  out += " Intel formula |\n|---|";
  for (size_t k = 0; k <= names.size(); ++k) out += "---|";
  return out + "\n";
}

std::string figure_row(const std::string& label, const std::vector<NoiseStats>& stats,
                       const std::function<double(const NoiseStats&)>& value, const char* format,
                       double formula = NAN) {
  std::string out = "| " + label + " |";
  for (const auto& s : stats) out += " " + cell(value(s), format) + " |";
  return out + " " + cell(formula, format) + " |\n";
}

// The image's rows: invalid pixels, the edge bands, invalid pixels at discontinuities and the shadows.
std::string band_and_shadow_rows(const std::vector<NoiseStats>& stats) {
  std::string out;
  out += figure_row(
      "invalid pixels (%)", stats, [](const NoiseStats& s) { return 100.0 * s.invalid_fraction; }, "%.1f");
  out += figure_row(
      "left band (px)", stats, [](const NoiseStats& s) { return s.bands.left_px; }, "%.0f");
  out += figure_row(
      "left band, geometric fx*b/z (px)", stats, [](const NoiseStats& s) { return s.left_band_geometric_px; }, "%.1f");
  out += figure_row(
      "right / top / bottom band (px)", stats,
      [](const NoiseStats& s) { return s.bands.right_px + s.bands.top_px + s.bands.bottom_px; }, "%.0f");
  out += figure_row(
      "invalid at discontinuities (% of inner invalid)", stats,
      [](const NoiseStats& s) { return 100.0 * s.holes.fraction_of_invalid; }, "%.1f");
  out += figure_row(
      "of them background on the left (%)", stats,
      [](const NoiseStats& s) {
        return 100.0 * double(s.holes.far_left_px) / double(s.holes.far_left_px + s.holes.far_right_px);
      },
      "%.1f");
  out += figure_row(
      "shadow run, median (px)", stats, [](const NoiseStats& s) { return s.holes.median_run_px; }, "%.0f");
  out += figure_row(
      "shadow, geometric median (px)", stats, [](const NoiseStats& s) { return s.holes.median_geometric_px; }, "%.1f");
  return out;
}

// One camera's cell of depth bin k: its figure in mm, its ratio to Intel's formula (each sample at its own depth;
// `mad`: the MAD sigma, its ratio at the samples' mean depth) and the samples' mean depth; "-" without one.
std::string depth_bin_cell(const std::vector<sensors::DepthBinStat>& bins, size_t k, bool mad, double fx_px,
                           const NoiseStatsOptions& options) {
  if (k >= bins.size() || !std::isfinite(bins[k].value_m)) return " - |";
  if (mad) {
    const double value = bins[k].mad_sigma_m;
    return " " + cell(kMmPerMetre * value, "%.2f") + " (x" +
           cell(value / intel_rms_m(bins[k].mean_depth_m, fx_px, options), "%.2f") + ") |";
  }
  return " " + cell(kMmPerMetre * bins[k].value_m, "%.2f") + " (x" + cell(bins[k].ratio_to_z2_law, "%.2f") + ", " +
         cell(bins[k].mean_depth_m, "%.2f") + " m) |";
}

// One row per depth bin for each of plane-fit RMS, temporal sigma and temporal MAD sigma.
std::string depth_bin_rows(const std::vector<NoiseStats>& stats, double fx_px, const NoiseStatsOptions& options) {
  std::string out;
  const auto bin_row = [&](const char* label_format, std::vector<sensors::DepthBinStat> NoiseStats::*member, bool mad) {
    for (size_t k = 0; k < options.bin_centres_m.size(); ++k) {
      char label[64];
      std::snprintf(label, sizeof label, label_format, options.bin_centres_m[k]);
      out += "| " + std::string(label) + " |";
      for (const auto& s : stats) out += depth_bin_cell(s.*member, k, mad, fx_px, options);
      out += " " + cell(kMmPerMetre * intel_rms_m(options.bin_centres_m[k], fx_px, options), "%.2f") + " |\n";
    }
  };
  bin_row("plane-fit RMS, %.1f m bin (mm)", &NoiseStats::plane_fit_rms, false);
  bin_row("temporal sigma, %.1f m bin (mm)", &NoiseStats::temporal_sigma, false);
  bin_row("temporal 1.4826 MAD / sqrt 2, %.1f m bin (mm)", &NoiseStats::temporal_sigma, true);
  return out;
}

}  // namespace

std::string noise_stats_table(const std::vector<std::string>& names, const std::vector<NoiseStats>& stats, double fx_px,
                              const NoiseStatsOptions& options) {
  return noise_table_header(names) + band_and_shadow_rows(stats) + depth_bin_rows(stats, fx_px, options);
}

}  // namespace stvl::analysis

#include "analysis/noise_stats.hpp"

#include <cmath>
#include <cstdio>
#include <functional>
#include <stdexcept>

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
  s.plane_fit_rms = sensors::plane_fit_rms_m(first, options.bin_centres_m, options.bin_half_width_m, 12, 0.25, 5,
                                             intel_at_1m_m);
  s.temporal_sigma = sensors::temporal_sigma_m(first, second, options.bin_centres_m, options.bin_half_width_m, 100,
                                               intel_at_1m_m);
  return s;
}

nlohmann::json to_json(const NoiseStats& s, double fx_px, const NoiseStatsOptions& options) {
  const auto& h = s.holes;
  return {{"invalid_fraction", s.invalid_fraction},
          {"edge_bands_px",
           {{"left", s.bands.left_px}, {"right", s.bands.right_px}, {"top", s.bands.top_px}, {"bottom", s.bands.bottom_px}}},
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

std::string noise_stats_table(const std::vector<std::string>& names, const std::vector<NoiseStats>& stats,
                              double fx_px, const NoiseStatsOptions& options) {
  std::string out = "| figure |";
  for (const auto& n : names) out += " " + n + " |";
  out += " Intel formula |\n|---|";
  for (size_t k = 0; k <= names.size(); ++k) out += "---|";
  out += "\n";
  auto row = [&](const std::string& label, const std::function<double(const NoiseStats&)>& value, const char* format,
                 double formula = NAN) {
    out += "| " + label + " |";
    for (const auto& s : stats) out += " " + cell(value(s), format) + " |";
    out += " " + cell(formula, format) + " |\n";
  };
  // A depth bin: each camera's figure in mm, its ratio to Intel's formula (each sample at its own depth) and the
  // samples' mean depth.
  auto bin_row = [&](const std::string& label, std::vector<sensors::DepthBinStat> NoiseStats::*member, size_t k,
                     bool mad = false) {
    out += "| " + label + " |";
    for (const auto& s : stats) {
      const auto& bins = s.*member;
      if (k >= bins.size() || !std::isfinite(bins[k].value_m)) {
        out += " - |";
        continue;
      }
      if (mad) {  // ratio at the samples' mean depth
        const double value = bins[k].mad_sigma_m;
        out += " " + cell(1e3 * value, "%.2f") + " (x" +
               cell(value / intel_rms_m(bins[k].mean_depth_m, fx_px, options), "%.2f") + ") |";
        continue;
      }
      out += " " + cell(1e3 * bins[k].value_m, "%.2f") + " (x" + cell(bins[k].ratio_to_z2_law, "%.2f") + ", " +
             cell(bins[k].mean_depth_m, "%.2f") + " m) |";
    }
    out += " " + cell(1e3 * intel_rms_m(options.bin_centres_m[k], fx_px, options), "%.2f") + " |\n";
  };
  row("invalid pixels (%)", [](const NoiseStats& s) { return 100.0 * s.invalid_fraction; }, "%.1f");
  row("left band (px)", [](const NoiseStats& s) { return s.bands.left_px; }, "%.0f");
  row("left band, geometric fx*b/z (px)", [](const NoiseStats& s) { return s.left_band_geometric_px; }, "%.1f");
  row("right / top / bottom band (px)",
      [](const NoiseStats& s) { return s.bands.right_px + s.bands.top_px + s.bands.bottom_px; }, "%.0f");
  row("invalid at discontinuities (% of inner invalid)",
      [](const NoiseStats& s) { return 100.0 * s.holes.fraction_of_invalid; }, "%.1f");
  row("of them background on the left (%)", [](const NoiseStats& s) {
    return 100.0 * double(s.holes.far_left_px) / double(s.holes.far_left_px + s.holes.far_right_px);
  }, "%.1f");
  row("shadow run, median (px)", [](const NoiseStats& s) { return s.holes.median_run_px; }, "%.0f");
  row("shadow, geometric median (px)", [](const NoiseStats& s) { return s.holes.median_geometric_px; }, "%.1f");
  for (size_t k = 0; k < options.bin_centres_m.size(); ++k) {
    char label[64];
    std::snprintf(label, sizeof label, "plane-fit RMS, %.1f m bin (mm)", options.bin_centres_m[k]);
    bin_row(label, &NoiseStats::plane_fit_rms, k);
  }
  for (size_t k = 0; k < options.bin_centres_m.size(); ++k) {
    char label[64];
    std::snprintf(label, sizeof label, "temporal sigma, %.1f m bin (mm)", options.bin_centres_m[k]);
    bin_row(label, &NoiseStats::temporal_sigma, k);
  }
  for (size_t k = 0; k < options.bin_centres_m.size(); ++k) {
    char label[64];
    std::snprintf(label, sizeof label, "temporal 1.4826 MAD / sqrt 2, %.1f m bin (mm)", options.bin_centres_m[k]);
    bin_row(label, &NoiseStats::temporal_sigma, k, true);
  }
  return out;
}

}  // namespace stvl::analysis

#pragma once
// The figures of `stvl-bench noise-stats` for one camera (real or simulated): two frames of a static camera
// reduced by sensors/depth_stats.hpp, with Intel's RMS formula beside each depth bin, as JSON and as a table.
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "sensors/camera.hpp"
#include "sensors/depth_image.hpp"
#include "sensors/depth_stats.hpp"

namespace stvl::analysis {

struct NoiseStatsOptions {
  double baseline_m = 0.050;  // for the geometric band and shadow widths and Intel's formula
  double subpixel = 0.08;     // Intel's formula: z^2 * subpixel / (fx * baseline)
  double min_jump_m = 0.10;   // a depth discontinuity
  std::vector<double> bin_centres_m = {0.5, 1.0, 1.5, 2.0, 2.5, 3.0};
  double bin_half_width_m = 0.25;
};

struct NoiseStats {
  double invalid_fraction = 0;
  sensors::EdgeBandsPx bands;
  double left_band_geometric_px = 0;  // fx * baseline / z at the band's edge (median over rows)
  sensors::DiscontinuityHoles holes;
  std::vector<sensors::DepthBinStat> plane_fit_rms;   // of the first frame
  std::vector<sensors::DepthBinStat> temporal_sigma;  // between the two frames
};

// Throws std::invalid_argument when the frames' sizes differ from each other or from the intrinsics.
NoiseStats compute_noise_stats(const sensors::DepthImage& first, const sensors::DepthImage& second,
                               const sensors::CameraIntrinsics& intrinsics, const NoiseStatsOptions& options);

// Intel's RMS depth error at z.
double intel_rms_m(double z_m, double fx_px, const NoiseStatsOptions& options);

nlohmann::json to_json(const NoiseStats& stats, double fx_px, const NoiseStatsOptions& options);

// Side by side: one column per named camera, a last column with Intel's formula where it applies (at the bin's
// centre; each camera's depth-bin cells give their ratio to it, each sample at its own depth, and their mean depth).
std::string noise_stats_table(const std::vector<std::string>& names, const std::vector<NoiseStats>& stats, double fx_px,
                              const NoiseStatsOptions& options);

}  // namespace stvl::analysis

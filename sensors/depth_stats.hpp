#pragma once
// Statistics of depth images for holding a noise model against a real camera (stvl-bench noise-stats): invalid
// pixels, invalid bands along the image edges, holes beside depth discontinuities, plane-fit RMS over flat patches
// and the temporal noise between two frames of a static camera, binned by depth.
#include "sensors/depth_image.hpp"

#include <vector>

namespace stvl::sensors {

double invalid_fraction(const DepthImage& image);

// Width of the invalid band along each edge: the median over rows (left, right) or columns (top, bottom) of the
// run of invalid pixels that touches that edge (0 where the edge pixel is valid).
struct EdgeBandsPx {
  double left_px = 0, right_px = 0, top_px = 0, bottom_px = 0;
};
EdgeBandsPx invalid_edge_bands_px(const DepthImage& image);

// Median over rows of the geometric left band at the depth z of the row's first valid pixel: the disparity
// fx * baseline / z (px) that a point needs to be seen by the right imager too. NaN when no row has a valid pixel.
double left_band_geometric_px(const DepthImage& image, double fx_px, double baseline_m);

// Runs of invalid pixels within a row bounded by two valid pixels whose depths differ by more than min_jump_m
// (a depth discontinuity). The far side is the side of the larger depth (the background).
struct DiscontinuityHoles {
  long runs = 0;
  long invalid_px = 0;             // invalid pixels in those runs
  double fraction_of_invalid = 0;  // invalid_px / invalid pixels that are not in a left or right edge band
  long far_left_px = 0;            // invalid pixels in runs whose background is on the left (shadow left of the
  long far_right_px = 0;           // foreground edge) / on the right
  double median_run_px = 0;        // median run length of the far-left runs (0 if none)
  double median_geometric_px = 0;  // median of fx * baseline * (1 / z_near - 1 / z_far) over the same runs
};
DiscontinuityHoles discontinuity_holes(const DepthImage& image, double min_jump_m, double fx_px, double baseline_m);

// A figure per depth bin [centre - half_width, centre + half_width).
struct DepthBinStat {
  double centre_m = 0;
  long samples = 0;         // pixels (temporal) or patches (plane fit) in the bin
  double mean_depth_m = 0;  // of those samples (NaN when none): a bin's samples need not sit at its centre
  double value_m = 0;       // NaN when samples < the minimum asked for
  // With sigma_at_1m_m > 0 (a z^2 law, e.g. Intel's RMS formula z^2 * subpixel / (fx * baseline)): the same
  // statistic over each sample divided by sigma_at_1m_m * z^2, so that samples at different depths within the bin
  // are each held against the law at their own depth. NaN otherwise.
  double ratio_to_z2_law = 0;
  double mad_sigma_m = 0;  // temporal_sigma_m only: 1.4826 * MAD(a - b) / sqrt(2), biased low on quantized depth
};

// Robust temporal sigma between two frames of a static camera: over pixels valid in both, binned by their mean
// depth, the RMS of a - b about its median over the differences within 4 * 1.4826 * MAD of it, / sqrt(2) (outliers
// out, unbiased on quantized depth, unlike the MAD itself: mad_sigma_m). Sizes must match (std::invalid_argument).
std::vector<DepthBinStat> temporal_sigma_m(const DepthImage& a, const DepthImage& b,
                                           const std::vector<double>& centres_m, double half_width_m,
                                           long min_samples = 100, double sigma_at_1m_m = 0);

// Plane fits over square patches of patch_px x patch_px (tiling the image, no overlap): a patch is flat when all
// its pixels are valid and its depth range is below max_range_fraction of its mean depth; 1/z is fitted as a
// linear function of (u, v) (exact for a plane seen by a pinhole camera), and the patch's RMS residual in depth
// goes to the bin of its mean depth. value_m is the median patch RMS in the bin.
std::vector<DepthBinStat> plane_fit_rms_m(const DepthImage& image, const std::vector<double>& centres_m,
                                          double half_width_m, int patch_px = 12, double max_range_fraction = 0.25,
                                          long min_samples = 5, double sigma_at_1m_m = 0);

}  // namespace stvl::sensors

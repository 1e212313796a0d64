#include "sensors/depth_stats.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace stvl::sensors {
namespace {

DepthImage filled(int width, int height, float z_m) {
  DepthImage image(width, height);
  std::fill(image.depth_m.begin(), image.depth_m.end(), z_m);
  return image;
}

TEST(DepthStats, InvalidFractionAndEdgeBands) {
  // 60 x 40 at 2 m: the 7 leftmost columns, the 2 rightmost and the 4 bottom rows invalid.
  DepthImage image = filled(60, 40, 2.0f);
  for (int v = 0; v < 40; ++v)
    for (int u = 0; u < 60; ++u)
      if (u < 7 || u >= 58 || v >= 36) image.at(u, v) = 0.0f;
  EXPECT_NEAR(invalid_fraction(image), 1.0 - (51.0 * 36.0) / (60.0 * 40.0), 1e-12);
  const EdgeBandsPx bands = invalid_edge_bands_px(image);
  EXPECT_EQ(bands.left_px, 7.0);
  EXPECT_EQ(bands.right_px, 2.0);
  EXPECT_EQ(bands.top_px, 0.0);
  EXPECT_EQ(bands.bottom_px, 4.0);
  // The band's geometric width at the depth of its edge: fx * b / z = 400 * 0.05 / 2 = 10 px.
  EXPECT_NEAR(left_band_geometric_px(image, 400.0, 0.05), 10.0, 1e-9);
  EXPECT_TRUE(std::isnan(left_band_geometric_px(filled(5, 5, 0.0f), 400.0, 0.05)));
}

// A step edge: background at 2 m on the left, foreground at 1 m from column 35, a 5 px hole between them in
// every row; on the right of the foreground a 3 px hole within it (no jump) and then a mirrored step.
TEST(DepthStats, HolesAtDiscontinuitiesAndTheirSide) {
  const int W = 80, H = 10;
  DepthImage image(W, H);
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) image.at(u, v) = u < 30 ? 2.0f : (u < 35 ? 0.0f : 1.0f);
    for (int u = 45; u < 48; ++u) image.at(u, v) = 0.0f;  // within the foreground: not a discontinuity
    image.at(60, v) = image.at(61, v) = 0.0f;             // foreground 1 m | hole | background 2.5 m
    for (int u = 62; u < W; ++u) image.at(u, v) = 2.5f;
  }
  const DiscontinuityHoles holes = discontinuity_holes(image, 0.1, 400.0, 0.05);
  EXPECT_EQ(holes.runs, 2 * H);
  EXPECT_EQ(holes.far_left_px, 5 * H);
  EXPECT_EQ(holes.far_right_px, 2 * H);
  EXPECT_EQ(holes.invalid_px, 7 * H);
  EXPECT_NEAR(holes.fraction_of_invalid, 7.0 / 10.0, 1e-12);
  EXPECT_EQ(holes.median_run_px, 5.0);
  EXPECT_NEAR(holes.median_geometric_px, 400.0 * 0.05 * (1.0 / 1.0 - 1.0 / 2.0), 1e-9);  // 10 px
}

TEST(DepthStats, PlaneFitRmsIsExactForPlanesAndMeasuresKnownNoise) {
  const int W = 120, H = 96;
  // A tilted plane seen by a pinhole camera: 1 / z is linear in (u, v). Depths 1.3 to 1.7 m.
  DepthImage plane(W, H);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) plane.at(u, v) = float(1.0 / (1.0 / 1.3 - 0.0014 * u - 0.0008 * v));
  const std::vector<double> centres = {1.0, 1.5, 2.0};
  const auto clean = plane_fit_rms_m(plane, centres, 0.25);
  EXPECT_TRUE(std::isnan(clean[0].value_m));
  ASSERT_GE(clean[1].samples, 5);
  EXPECT_LT(clean[1].value_m, 2e-6);  // float storage only

  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.004);
  DepthImage noisy = plane;
  for (float& z : noisy.depth_m) z = float(z + noise(rng));
  const auto measured = plane_fit_rms_m(noisy, centres, 0.25);
  // Residual RMS of a 3-parameter fit over 144 pixels: sigma * sqrt(141 / 144); the median over patches scatters
  // by about 6 % per patch / sqrt(patches).
  EXPECT_NEAR(measured[1].value_m, 0.004 * std::sqrt(141.0 / 144.0), 0.004 * 0.05);
}

TEST(DepthStats, TemporalSigmaOfTwoFrames) {
  const int W = 200, H = 100;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.005);
  DepthImage a(W, H), b(W, H);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const double z = u < W / 2 ? 1.0 : 2.0;  // half at 1 m with 5 mm noise, half at 2 m with 10 mm
      a.at(u, v) = float(z + (u < W / 2 ? 1.0 : 2.0) * noise(rng));
      b.at(u, v) = float(z + (u < W / 2 ? 1.0 : 2.0) * noise(rng));
    }
  a.at(0, 0) = 0.0f;  // invalid in one frame: not counted
  const auto sigma = temporal_sigma_m(a, b, {1.0, 2.0, 3.0}, 0.25);
  EXPECT_EQ(sigma[0].samples, W / 2 * H - 1);
  EXPECT_EQ(sigma[1].samples, W / 2 * H);
  EXPECT_EQ(sigma[2].samples, 0);
  // 10^4 samples: the MAD-based sigma scatters by about 1.2 %; 5 % is 4 of those.
  EXPECT_NEAR(sigma[0].value_m, 0.005, 0.005 * 0.05);
  EXPECT_NEAR(sigma[1].value_m, 0.010, 0.010 * 0.05);
  EXPECT_TRUE(std::isnan(sigma[2].value_m));
  // Against a z^2 law with 5 mm at 1 m, each pixel at its own depth: x1.0 at 1 m, x0.5 at 2 m (10 mm vs 20 mm).
  const auto ratio = temporal_sigma_m(a, b, {1.0, 2.0}, 0.25, 100, 0.005);
  EXPECT_NEAR(ratio[0].ratio_to_z2_law, 1.0, 0.05);
  EXPECT_NEAR(ratio[1].ratio_to_z2_law, 0.5, 0.025);
  // Quantized depth (a 3 mm grid for a 5 mm sigma, as the simulated D435's 1/32 px disparity steps are at 1 m):
  // still 5 mm, within 5 %.
  DepthImage qa = a, qb = b;
  for (DepthImage* image : {&qa, &qb})
    for (float& z : image->depth_m) z = z > 0.0f ? float(0.003 * std::round(z / 0.003)) : 0.0f;
  EXPECT_NEAR(temporal_sigma_m(qa, qb, {1.0}, 0.25)[0].value_m, 0.005, 0.005 * 0.05);
  EXPECT_THROW(temporal_sigma_m(a, DepthImage(3, 3), {1.0}, 0.25), std::invalid_argument);
}

}  // namespace
}  // namespace stvl::sensors

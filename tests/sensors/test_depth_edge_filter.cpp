// The depth-edge filter on tiny synthetic depth images: flying pixels between two surfaces go, slanted planes
// stay, the threshold grows with depth^2, invalid pixels stay invalid, and the parallel version equals the
// plain reference (sensors/reference/).
#include "sensors/depth_edge_filter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "sensors/depth_noise.hpp"
#include "sensors/reference/depth_edge_filter.hpp"

namespace stvl::sensors {
namespace {

DepthEdgeFilterConfig enabled(double max_jump_at_1m_m = 0.03) {
  DepthEdgeFilterConfig config;
  config.enabled = true;
  config.max_jump_at_1m_m = max_jump_at_1m_m;
  return config;
}

// Both versions, checked equal; returns the parallel one's image.
DepthImage filtered(const DepthEdgeFilterConfig& config, const DepthImage& in, std::size_t* dropped = nullptr) {
  DepthImage out, reference;
  const std::size_t n = filter_depth_edges(config, in, out);
  const std::size_t n_reference = reference::filter_depth_edges(config, in, reference);
  EXPECT_EQ(n, n_reference);
  EXPECT_EQ(out.width, in.width);
  EXPECT_EQ(out.height, in.height);
  EXPECT_EQ(out.depth_m.size(), reference.depth_m.size());
  for (std::size_t i = 0; i < out.depth_m.size() && i < reference.depth_m.size(); ++i) {
    const float a = out.depth_m[i], b = reference.depth_m[i];
    EXPECT_TRUE(a == b || (std::isnan(a) && std::isnan(b))) << "pixel " << i << ": " << a << " vs " << b;
  }
  if (dropped) *dropped = n;
  return out;
}

// Columns u < edge_u at near_m, the rest at far_m.
DepthImage step(int width, int height, int edge_u, float near_m, float far_m) {
  DepthImage image(width, height);
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) image.at(u, v) = u < edge_u ? near_m : far_m;
  return image;
}

TEST(DepthEdgeFilter, FlyingPixelBetweenTwoSurfacesIsRemoved) {
  // A box 1 m away in front of a wall at 3 m; one pixel of the wall's rim flew to 2 m, into free space.
  DepthImage image = step(12, 7, 6, 1.0f, 3.0f);
  image.at(6, 3) = 2.0f;
  std::size_t dropped = 0;
  const DepthImage out = filtered(enabled(), image, &dropped);
  EXPECT_EQ(out.at(6, 3), 0.0f) << "the flying pixel stays";
  // Also dropped (documented): the rims on both sides of the jump (columns 5 and 6) and the wall pixels beside
  // the flying one (column 7, rows 2 to 4). Every other pixel stays as it was.
  for (int v = 0; v < 7; ++v)
    for (int u = 0; u < 12; ++u) {
      const bool drop = u == 5 || u == 6 || (u == 7 && v >= 2 && v <= 4);
      EXPECT_EQ(out.at(u, v), drop ? 0.0f : image.at(u, v)) << u << ", " << v;
    }
  EXPECT_EQ(dropped, 17u);
  // No point is left between the two surfaces.
  for (float z : out.depth_m) EXPECT_TRUE(z == 0.0f || z == 1.0f || z == 3.0f) << z;
}

TEST(DepthEdgeFilter, DisabledIsACopy) {
  DepthImage image = step(8, 4, 4, 1.0f, 3.0f);
  image.at(4, 2) = 2.0f;
  DepthEdgeFilterConfig off;
  std::size_t dropped = 1;
  const DepthImage out = filtered(off, image, &dropped);
  EXPECT_EQ(dropped, 0u);
  EXPECT_EQ(out.depth_m, image.depth_m);
}

// The plane through (0, 0, centre_m) whose normal is tilted tilt_deg from the optical axis about the camera's
// y axis, rendered exactly with the given intrinsics up to their max range (0 beyond, as the camera reads).
DepthImage slanted_plane(const CameraIntrinsics& k, double centre_m, double tilt_deg) {
  const double tilt = tilt_deg * M_PI / 180.0;
  const double nx = std::sin(tilt), nz = std::cos(tilt);  // unit normal n; plane n . X = nz * centre_m
  const double d = nz * centre_m;
  DepthImage image(k.width, k.height);
  for (int v = 0; v < k.height; ++v)
    for (int u = 0; u < k.width; ++u) {
      const double x = (u - k.cx) / k.fx;  // ray (x, y, 1): depth z = d / (n . ray)
      const double denominator = nx * x + nz;
      const double z = denominator > 0.0 ? d / denominator : 0.0;
      image.at(u, v) = z <= k.max_range_m ? float(z) : 0.0f;
    }
  return image;
}

TEST(DepthEdgeFilter, SlantedPlaneAt4mWithStereoNoiseIsNotThinned) {
  const CameraIntrinsics k = CameraIntrinsics::d435_848x480();
  // 60 degrees from facing the camera: the plane passes 2 m from the optical centre, neighbouring pixels differ
  // by 1.6 cm at 4 m (z^2 * sin 60 / (f * 2 m)), and the stereo noise of two pixels by 8.4 cm RMS at 4 m.
  const DepthImage clean = slanted_plane(k, 4.0, 60.0);
  std::size_t dropped = 1;
  filtered(enabled(), clean, &dropped);
  EXPECT_EQ(dropped, 0u) << "the noise-free plane is thinned";

  DepthNoiseConfig stereo;  // the D435 model's disparity noise and quantization only
  stereo.edge_probability = 0.0;
  stereo.dropout_probability = 0.0;
  stereo.holes_per_frame = 0.0;
  DepthNoise noise(stereo, k);
  DepthImage noisy = clean;
  noise.apply(noisy, 7, 0);
  const int valid = noisy.valid_count();
  ASSERT_GT(valid, k.width * k.height / 2);
  filtered(enabled(), noisy, &dropped);
  EXPECT_LT(double(dropped), 1e-4 * valid) << dropped << " of " << valid << " pixels dropped";
}

TEST(DepthEdgeFilter, OnlyPlanesPassingCloseToTheCameraAreThinned) {
  // Seen almost edge on, the plane passes d = 4 m * cos(tilt) from the optical centre and its neighbouring
  // pixels differ by about z^2 / (f * d): above the threshold 0.03 * z^2 when d < 1 / (f * 0.03) = 7.7 cm.
  const CameraIntrinsics k = CameraIntrinsics::d435_848x480();
  std::size_t dropped = 1;
  filtered(enabled(), slanted_plane(k, 4.0, 88.0), &dropped);  // d = 14 cm: 0.017 z^2 steps
  EXPECT_EQ(dropped, 0u);
  const DepthImage grazing = slanted_plane(k, 4.0, 89.5);  // d = 3.5 cm: 0.066 z^2 steps
  filtered(enabled(), grazing, &dropped);
  EXPECT_GT(double(dropped), 0.9 * grazing.valid_count());
  filtered(enabled(0.3), grazing, &dropped);  // a threshold 10 x higher keeps it
  EXPECT_EQ(dropped, 0u);
}

TEST(DepthEdgeFilter, ThresholdGrowsWithDepthSquared) {
  const DepthEdgeFilterConfig config = enabled(0.03);
  EXPECT_DOUBLE_EQ(config.jump_threshold_m(1.0), 0.03);
  EXPECT_DOUBLE_EQ(config.jump_threshold_m(2.0), 4 * config.jump_threshold_m(1.0));
  EXPECT_DOUBLE_EQ(config.jump_threshold_m(4.0), 16 * config.jump_threshold_m(1.0));
  // A step from z to z + jump: 10 % below the threshold at z, both sides stay; 10 % above, the near side goes
  // (the far side compares the same jump with its own threshold, larger).
  for (float z : {0.5f, 1.0f, 2.0f, 4.0f, 6.0f}) {
    SCOPED_TRACE(z);
    const double threshold = config.jump_threshold_m(z);
    std::size_t dropped = 1;
    filtered(config, step(6, 3, 3, z, float(z + 0.9 * threshold)), &dropped);
    EXPECT_EQ(dropped, 0u) << "a step of 0.9 x the threshold thins the image";
    const float far = float(z + 1.1 * threshold);
    const DepthImage out = filtered(config, step(6, 3, 3, z, far), &dropped);
    const bool far_goes = far - z > config.jump_threshold_m(far);
    for (int v = 0; v < 3; ++v) {
      EXPECT_EQ(out.at(2, v), 0.0f) << "a step of 1.1 x the threshold is kept";
      EXPECT_EQ(out.at(3, v), far_goes ? 0.0f : far);
      EXPECT_EQ(out.at(1, v), z);
    }
    EXPECT_EQ(dropped, far_goes ? 6u : 3u);
  }
  // A jump of 0.2 m is an edge at 1 m and noise at 4 m.
  std::size_t dropped = 0;
  filtered(config, step(6, 3, 3, 1.0f, 1.2f), &dropped);
  EXPECT_EQ(dropped, 6u);
  filtered(config, step(6, 3, 3, 4.0f, 4.2f), &dropped);
  EXPECT_EQ(dropped, 0u);
}

TEST(DepthEdgeFilter, InvalidPixelsStayInvalidAndDoNotMakeEdges) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  DepthImage image(5, 5);
  std::fill(image.depth_m.begin(), image.depth_m.end(), 2.0f);
  image.at(0, 0) = 0.0f;   // no return
  image.at(2, 2) = nan;    // not a number
  image.at(4, 4) = -1.0f;  // negative
  image.at(4, 0) = 0.0f;
  std::size_t dropped = 1;
  const DepthImage out = filtered(enabled(), image, &dropped);
  EXPECT_EQ(dropped, 0u) << "a valid pixel beside an invalid one was dropped";
  EXPECT_EQ(out.at(0, 0), 0.0f);
  EXPECT_TRUE(std::isnan(out.at(2, 2)));
  EXPECT_EQ(out.at(4, 4), -1.0f);
  EXPECT_EQ(out.at(1, 1), 2.0f);
  // A pixel with no valid neighbour has nothing to jump from: it stays.
  DepthImage lone(3, 3);
  lone.at(1, 1) = 1.5f;
  EXPECT_EQ(filtered(enabled(), lone).at(1, 1), 1.5f);
  // Borders and 1-pixel images take the checked path.
  DepthImage one(1, 1);
  one.at(0, 0) = 1.0f;
  EXPECT_EQ(filtered(enabled(), one).at(0, 0), 1.0f);
  EXPECT_EQ(filtered(enabled(), step(2, 1, 1, 1.0f, 3.0f)).depth_m, (std::vector<float>{0.0f, 0.0f}));
}

TEST(DepthEdgeFilter, ParallelEqualsReferenceOnANoisyScene) {
  // Boxes at several depths in front of a wall, with the D435 model's noise (flying pixels, holes, dropouts);
  // 848x480 so that TBB splits the rows. filtered() compares the two versions pixel by pixel.
  const CameraIntrinsics k = CameraIntrinsics::d435_848x480();
  DepthImage clean(k.width, k.height);
  for (int v = 0; v < k.height; ++v)
    for (int u = 0; u < k.width; ++u) {
      float z = 5.0f + 0.002f * float(u);
      if (u > 100 && u < 300 && v > 200) z = 1.2f;
      if (u > 400 && u < 500 && v > 100 && v < 350) z = 2.5f + 0.001f * float(v);
      if (u > 600 && v < 150) z = 0.0f;
      clean.at(u, v) = z;
    }
  DepthNoise noise(DepthNoiseConfig{}, k);
  for (uint64_t frame = 0; frame < 3; ++frame) {
    DepthImage noisy = clean;
    noise.apply(noisy, 11, frame);
    std::size_t dropped = 0;
    const DepthImage out = filtered(enabled(), noisy, &dropped);
    EXPECT_GT(dropped, 0u);
    EXPECT_EQ(out.valid_count() + int(dropped), noisy.valid_count());
  }
}

TEST(DepthEdgeFilter, BadInputThrows) {
  for (double bad : {0.0, -0.03, std::nan(""), std::numeric_limits<double>::infinity()}) {
    EXPECT_THROW(enabled(bad).validate(), std::invalid_argument) << bad;
    DepthImage out;
    EXPECT_THROW(filter_depth_edges(enabled(bad), DepthImage(2, 2), out), std::invalid_argument) << bad;
  }
  try {
    enabled(-1.0).validate();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_jump_at_1m_m"), std::string::npos) << e.what();
  }
  DepthImage image(2, 2);
  EXPECT_THROW(filter_depth_edges(enabled(), image, image), std::invalid_argument);
  DepthImage broken(3, 3);
  broken.depth_m.resize(4);
  DepthImage out;
  EXPECT_THROW(filter_depth_edges(enabled(), broken, out), std::invalid_argument);
}

}  // namespace
}  // namespace stvl::sensors

#include "sensors/camera.hpp"
#include "sensors/depth_image.hpp"
#include "sensors/gl_context.hpp"
#include "sensors/reference/camera.hpp"

#include <gtest/gtest.h>

#include <tbb/task_arena.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <vector>

namespace stvl::sensors {
namespace {

constexpr double kDeg = M_PI / 180.0;

TEST(CameraIntrinsics, D435PresetsHaveSquarePixels) {
  for (const CameraIntrinsics& k : {CameraIntrinsics::d435_848x480(), CameraIntrinsics::d435_640x480()}) {
    EXPECT_NO_THROW(k.validate());
    EXPECT_TRUE(k.square_pixels());
    EXPECT_DOUBLE_EQ(k.min_range_m, 0.28);
    EXPECT_DOUBLE_EQ(k.max_range_m, 10.0);
  }
  EXPECT_NEAR(CameraIntrinsics::d435_848x480().vfov_rad(), 58.0 * kDeg, 1e-9);
  EXPECT_NEAR(CameraIntrinsics::d435_848x480().hfov_rad() / kDeg, 88.8, 0.1);
  EXPECT_NEAR(CameraIntrinsics::d435_848x480().fx, 433.0, 0.1);
}

// 640x480 is the real stream's geometry: the camera_info of the D435 bag in ../shared/realdata
// (fx = fy = 390.43145751953125, cx 331.38787841796875, cy 242.18734741210938).
TEST(CameraIntrinsics, D435At640x480IsTheRealStream) {
  const CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  EXPECT_NEAR(k.fx, 390.4315, 0.01);
  EXPECT_NEAR(k.fy, 390.4315, 0.01);
  EXPECT_NEAR(k.cx, 331.3879, 0.01);
  EXPECT_NEAR(k.cy, 242.1873, 0.01);
  EXPECT_NEAR(k.hfov_rad() / kDeg, 78.7, 0.1);
  EXPECT_NEAR(k.vfov_rad() / kDeg, 63.2, 0.1);
}

TEST(CameraIntrinsics, FromHfov) {
  const CameraIntrinsics k = CameraIntrinsics::from_hfov(640, 480, 87.0 * kDeg, 0.3, 8.0, 15.0);
  EXPECT_NEAR(k.hfov_rad(), 87.0 * kDeg, 1e-9);
  EXPECT_NEAR(k.fx, 320.0 / std::tan(43.5 * kDeg), 1e-9);
  EXPECT_THROW(CameraIntrinsics::from_hfov(640, 480, M_PI, 0.3, 8.0, 15.0), std::invalid_argument);
}

TEST(CameraIntrinsics, BadValuesThrowNamingTheField) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto expect_bad = [](CameraIntrinsics k, const std::string& field) {
    try {
      k.validate();
      ADD_FAILURE() << "no throw for " << field;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  auto with = [&](auto change) {
    CameraIntrinsics copy = k;
    change(copy);
    return copy;
  };
  expect_bad(with([](auto& c) { c.width = 0; }), "width");
  expect_bad(with([](auto& c) { c.height = -4; }), "height");
  expect_bad(with([](auto& c) { c.fx = 0.0; }), "fx");
  expect_bad(with([&](auto& c) { c.fy = nan; }), "fy");
  expect_bad(with([](auto& c) { c.fx = std::numeric_limits<double>::infinity(); }), "fx");
  expect_bad(with([](auto& c) { c.cx = 700.0; }), "cx");
  expect_bad(with([&](auto& c) { c.cy = nan; }), "cy");
  expect_bad(with([](auto& c) { c.min_range_m = 0.0; }), "min_range_m");
  expect_bad(with([](auto& c) { c.max_range_m = 0.2; }), "max_range_m");
  expect_bad(with([](auto& c) { c.rate_hz = 0.0; }), "rate_hz");
}

TEST(CameraIntrinsics, ProjectionInvertsPixelRay) {
  CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  k.cx = 301.25;
  k.cy = 255.5;
  k.fy = 410.0;  // projection itself supports non-square pixels
  for (double u : {0.0, 123.4, 639.0}) {
    for (double v : {0.0, 240.0, 479.0}) {
      const Eigen::Vector3d p_C = 2.5 * pixel_ray_C(k, u, v);
      const auto uv = project_to_pixel(k, p_C);
      ASSERT_TRUE(uv.has_value());
      EXPECT_NEAR(uv->x(), u, 1e-9);
      EXPECT_NEAR(uv->y(), v, 1e-9);
    }
  }
  EXPECT_FALSE(project_to_pixel(k, Eigen::Vector3d(0.1, 0.1, -1.0)).has_value());
}

TEST(DepthToCloud, RoundTripDropsInvalidPixels) {
  CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  k.cx = 290.0;  // off-centre principal point
  k.cy = 250.0;
  DepthImage image(k.width, k.height);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u)
      image.at(u, v) = ((u + v) % 7 == 0) ? 0.0f : 0.5f + 0.01f * float((u * 3 + v) % 300);
  }
  const Eigen::Matrix3Xf points_C = depth_to_cloud(image, k);
  ASSERT_EQ(points_C.cols(), image.valid_count());
  Eigen::Index column = 0;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      if (image.at(u, v) == 0.0f) continue;
      const Eigen::Vector3d p_C = points_C.col(column++).cast<double>();
      EXPECT_FLOAT_EQ(float(p_C.z()), image.at(u, v));
      const auto uv = project_to_pixel(k, p_C);
      ASSERT_TRUE(uv.has_value());
      ASSERT_NEAR(uv->x(), u, 1e-3);
      ASSERT_NEAR(uv->y(), v, 1e-3);
    }
  }
  Eigen::Matrix3Xf buffer;
  EXPECT_EQ(depth_to_cloud(image, k, buffer), points_C.cols());
  EXPECT_EQ(buffer.cols(), Eigen::Index(k.width) * k.height);
  EXPECT_TRUE(buffer.leftCols(points_C.cols()).isApprox(points_C));
  DepthImage wrong(10, 10);
  EXPECT_THROW(depth_to_cloud(wrong, k), std::invalid_argument);
}

// The parallel depth_to_cloud against its plain twin (sensors/reference/): the same points in row-major pixel order.
TEST(DepthToCloud, SameAsAPlainLoopInPixelOrder) {
  const CameraIntrinsics k = CameraIntrinsics::from_hfov(97, 61, 1.1, 0.1, 10.0, 30.0);
  DepthImage image(k.width, k.height);
  for (int v = 0; v < k.height; ++v)
    for (int u = 0; u < k.width; ++u)
      image.at(u, v) = (u * 7 + v * 3) % 5 == 0 ? 0.0f : (u % 11 == 0 ? NAN : 0.5f + 0.01f * float(u + v));
  Eigen::Matrix3Xf points;
  const Eigen::Index n = depth_to_cloud(image, k, points);
  const Eigen::Matrix3Xf expected = reference::depth_to_cloud(image, k);
  ASSERT_EQ(n, expected.cols());
  for (Eigen::Index i = 0; i < n; ++i) ASSERT_EQ(Eigen::Vector3f(points.col(i)), Eigen::Vector3f(expected.col(i))) << i;
}

// The vectorised, branch-free depth_to_cloud against its plain twin on images of every kind: odd and degenerate
// sizes, no valid pixel at all, blocks of rows without one, invalid last pixels, and depths of 0, -0, negative,
// NaN, +-Inf, subnormal, huge and FLT_MAX; on 1 to 3 threads, into fresh and reused (larger, dirty) buffers.
TEST(DepthToCloud, SameAsAPlainLoopOnVariedImages) {
  std::uint64_t state = 77;
  auto next = [&] {  // splitmix64
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  };
  auto uniform = [&] { return double(next() >> 11) * 0x1.0p-53; };
  const float inf = std::numeric_limits<float>::infinity();
  const float special[] = {0.0f, -0.0f, -1.0f, NAN, inf, -inf, 1e-40f, 1e30f, std::numeric_limits<float>::max()};
  const int sizes[][2] = {{1, 1}, {1, 40}, {37, 1}, {2, 17}, {17, 33}, {97, 61}, {848, 480}, {641, 35}};
  int trial = 0;
  for (const auto& size : sizes) {
    for (int kind = 0; kind < 6; ++kind, ++trial) {
      const CameraIntrinsics k = CameraIntrinsics::from_hfov(size[0], size[1], 0.3 + uniform(), 0.1, 10.0, 30.0);
      DepthImage image(k.width, k.height);
      const double invalid = kind == 0 ? 0.0 : (kind == 1 ? 1.0 : uniform() * 0.5);
      for (int v = 0; v < k.height; ++v)
        for (int u = 0; u < k.width; ++u) {
          float z = float(0.2 + 9.0 * uniform());
          if (uniform() < invalid) z = special[next() % 6];
          if (kind == 2 && uniform() < 0.1) z = special[next() % 9];          // the valid odd values too
          if (kind == 3 && v >= 16 && v < 40) z = 0.0f;                       // blocks of rows without a point
          if (kind == 4 && (u + 1 == k.width || v + 1 == k.height)) z = NAN;  // invalid last pixels and rows
          image.at(u, v) = z;
        }
      const Eigen::Matrix3Xf expected = reference::depth_to_cloud(image, k);
      for (int threads : {1, 2, 3}) {
        tbb::task_arena arena(threads);
        Eigen::Matrix3Xf fresh, reused = Eigen::Matrix3Xf::Constant(3, Eigen::Index(k.width) * k.height + 5, 7.0f);
        Eigen::Index n_fresh = 0, n_reused = 0, n_fused = 0;
        Eigen::Matrix3Xf fused_C, fused_W = Eigen::Matrix3Xf::Constant(3, 9, 7.0f);
        Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
        T.linear() =
            Eigen::AngleAxisd(6.0 * uniform(), Eigen::Vector3d(uniform(), uniform(), 1.0).normalized()).matrix();
        T.translation() = Eigen::Vector3d(20.0 * uniform() - 10.0, 20.0 * uniform() - 10.0, uniform());
        arena.execute([&] {
          n_fresh = depth_to_cloud(image, k, fresh);
          n_reused = depth_to_cloud(image, k, reused);
          n_fused = depth_to_cloud(image, k, fused_C, T, fused_W);
        });
        // The fused world points: Eigen's own expression on the plain points, bit for bit.
        ASSERT_EQ(n_fused, expected.cols()) << "trial " << trial;
        ASSERT_EQ(fused_W.cols(), expected.cols()) << "trial " << trial;
        const Eigen::Matrix3Xf expected_W =
            (T.linear().cast<float>() * expected).colwise() + T.translation().cast<float>();
        ASSERT_EQ(n_fresh, expected.cols()) << "trial " << trial;
        ASSERT_EQ(n_reused, expected.cols()) << "trial " << trial;
        EXPECT_EQ(reused.cols(), Eigen::Index(k.width) * k.height + 5);  // kept, not shrunk
        const std::size_t bytes = sizeof(float) * 3 * std::size_t(expected.cols());
        if (bytes == 0) continue;  // an empty matrix's data() may be null, which memcmp must not get
        EXPECT_EQ(std::memcmp(fresh.data(), expected.data(), bytes), 0) << "trial " << trial << " threads " << threads;
        EXPECT_EQ(std::memcmp(reused.data(), expected.data(), bytes), 0) << "trial " << trial << " threads " << threads;
        EXPECT_EQ(std::memcmp(fused_C.data(), expected.data(), bytes), 0)
            << "trial " << trial << " threads " << threads;
        EXPECT_EQ(std::memcmp(fused_W.data(), expected_W.data(), bytes), 0)
            << "trial " << trial << " threads " << threads;
      }
    }
  }
}

TEST(DepthPng, MillimetreRoundTripAndColorized) {
  DepthImage image(5, 3);
  const float values[] = {0.0f, 0.28f, 1.2344f, 9.9996f, 70.0f};
  for (int v = 0; v < 3; ++v) {
    for (int u = 0; u < 5; ++u) image.at(u, v) = values[u] + (u > 0 ? 0.001f * v : 0.0f);
  }
  const std::string path = ::testing::TempDir() + "stvl_depth_mm.png";
  write_depth_png_mm(image, path);
  const DepthImage back = read_depth_png_mm(path);
  ASSERT_EQ(back.width, 5);
  ASSERT_EQ(back.height, 3);
  for (int v = 0; v < 3; ++v) {
    EXPECT_EQ(back.at(0, v), 0.0f);
    for (int u = 1; u < 4; ++u) EXPECT_NEAR(back.at(u, v), image.at(u, v), 0.0005 + 1e-6);
    EXPECT_FLOAT_EQ(back.at(4, v), 65.535f);  // saturated
  }
  const std::string color_path = ::testing::TempDir() + "stvl_depth_color.png";
  write_depth_png_colorized(image, color_path, 0.28, 10.0);
  std::ifstream file(color_path, std::ios::binary);
  char signature[8] = {};
  file.read(signature, 8);
  EXPECT_EQ(std::string(signature + 1, 3), "PNG");
  EXPECT_THROW(write_depth_png_colorized(image, color_path, 2.0, 1.0), std::invalid_argument);
  EXPECT_THROW(write_depth_png_mm(image, "/nonexistent_dir/x.png"), std::runtime_error);
  EXPECT_THROW(read_depth_png_mm(color_path), std::runtime_error);  // 8-bit RGB is not a depth PNG
  std::remove(path.c_str());
  std::remove(color_path.c_str());
}

TEST(GlBackend, Parse) {
  EXPECT_EQ(parse_gl_backend("auto"), GlBackend::kAuto);
  EXPECT_EQ(parse_gl_backend("egl"), GlBackend::kEgl);
  EXPECT_EQ(parse_gl_backend("osmesa"), GlBackend::kOsmesa);
  EXPECT_THROW(parse_gl_backend("glx"), std::invalid_argument);
  EXPECT_STREQ(to_string(GlBackend::kOsmesa), "osmesa");
}

}  // namespace
}  // namespace stvl::sensors

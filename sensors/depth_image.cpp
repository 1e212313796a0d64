#include "sensors/depth_image.hpp"

#include <tbb/parallel_for.h>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>

#include "common/png.hpp"
#include "common/transform_points.hpp"
#include "common/units.hpp"

namespace stvl::sensors {
namespace {

void check_image(const DepthImage& image) {
  if (image.width <= 0 || image.height <= 0 || image.depth_m.size() != size_t(image.width) * image.height) {
    throw std::invalid_argument("DepthImage: size " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                                " does not match " + std::to_string(image.depth_m.size()) + " depth values");
  }
}

void check_matches(const DepthImage& image, const CameraIntrinsics& intrinsics) {
  check_image(image);
  intrinsics.validate();
  if (image.width != intrinsics.width || image.height != intrinsics.height) {
    throw std::invalid_argument("depth_to_cloud: image " + std::to_string(image.width) + "x" +
                                std::to_string(image.height) + " does not match intrinsics " +
                                std::to_string(intrinsics.width) + "x" + std::to_string(intrinsics.height));
  }
}

// Polynomial fit of Google's Turbo colormap (t in [0, 1]).
void turbo(double t, unsigned char* rgb) {
  t = std::clamp(t, 0.0, 1.0);
  const double r =
      0.13572138 + t * (4.61539260 + t * (-42.66032258 + t * (132.13108234 + t * (-152.94239396 + t * 59.28637943))));
  const double g =
      0.09140261 + t * (2.19418839 + t * (4.84296658 + t * (-14.18503333 + t * (4.27729857 + t * 2.82956604))));
  const double b =
      0.10667330 + t * (12.64194608 + t * (-60.58204836 + t * (110.36276771 + t * (-89.90310912 + t * 27.34824973))));
  rgb[0] = static_cast<unsigned char>(std::lround(255.0 * std::clamp(r, 0.0, 1.0)));
  rgb[1] = static_cast<unsigned char>(std::lround(255.0 * std::clamp(g, 0.0, 1.0)));
  rgb[2] = static_cast<unsigned char>(std::lround(255.0 * std::clamp(b, 0.0, 1.0)));
}

}  // namespace

int DepthImage::valid_count() const {
  return int(std::count_if(depth_m.begin(), depth_m.end(), [](float z) { return z > 0.0f && std::isfinite(z); }));
}

namespace {

// A pixel with a return: finite depth > 0. Written without && so that loops over it vectorise.
inline bool valid_depth(float z) { return (z > 0.0f) & (z < std::numeric_limits<float>::infinity()); }

}  // namespace

namespace {

// depth_to_cloud's work; with T_world_camera, each block's points are also moved into points_W.
// Blocks of rows in parallel (TBB): each block's valid pixels counted, then each block's points written from its
// offset, so that the points keep row-major pixel order whatever the threads. Within a row the arithmetic runs
// over every pixel (vectorised, the same operations per pixel as one at a time), then the row is compacted.
Eigen::Index cloud_of(const DepthImage& image, const CameraIntrinsics& intrinsics, Eigen::Matrix3Xf& points_C,
                      const Eigen::Isometry3d* T_world_camera, Eigen::Matrix3Xf* points_W) {
  check_matches(image, intrinsics);
  const Eigen::Index n_pixels = Eigen::Index(image.width) * image.height;
  if (points_C.cols() < n_pixels) points_C.resize(3, n_pixels);
  const float inv_fx = float(1.0 / intrinsics.fx), inv_fy = float(1.0 / intrinsics.fy);
  const float cx = float(intrinsics.cx), cy = float(intrinsics.cy);
  const std::size_t width = std::size_t(image.width);
  std::vector<float> x_over_z(width);  // (u - cx) / fx, rounded as the per-pixel expression rounds it
  for (std::size_t u = 0; u < width; ++u) x_over_z[u] = (float(u) - cx) * inv_fx;
  float* out = points_C.data();
  const float* depth = image.depth_m.data();
  constexpr int kRowsPerBlock = 16;
  const int blocks = (image.height + kRowsPerBlock - 1) / kRowsPerBlock;
  auto block_end = [&](int b) { return std::size_t(std::min(image.height, (b + 1) * kRowsPerBlock)) * width; };
  std::vector<Eigen::Index> offset(size_t(blocks) + 1, 0);
  tbb::parallel_for(0, blocks, [&](int b) {
    Eigen::Index count = 0;
    for (std::size_t i = std::size_t(b) * kRowsPerBlock * width; i < block_end(b); ++i) count += valid_depth(depth[i]);
    offset[size_t(b) + 1] = count;
  });
  for (int b = 0; b < blocks; ++b) offset[size_t(b) + 1] += offset[size_t(b)];
  Eigen::Matrix3f R_W_C = Eigen::Matrix3f::Identity();
  Eigen::Vector3f t_W = Eigen::Vector3f::Zero();
  if (T_world_camera) {
    R_W_C = T_world_camera->linear().cast<float>();
    t_W = T_world_camera->translation().cast<float>();
    points_W->resize(3, offset.back());
  }
  tbb::parallel_for(0, blocks, [&](int b) {
    Eigen::Index n = offset[size_t(b)];
    const Eigen::Index limit = offset[size_t(b) + 1];
    if (n == limit) return;
    // Pixels up to the block's last valid one are copied without a branch, an invalid one to the slot that the
    // next valid pixel then overwrites: every write stays within the block's own slots.
    std::size_t last = block_end(b) - 1;
    while (!valid_depth(depth[last])) --last;
    std::vector<float> row(2 * width);
    float* __restrict xs = row.data();
    float* __restrict ys = xs + width;
    const float* __restrict ax = x_over_z.data();
    for (std::size_t v = std::size_t(b) * kRowsPerBlock; v * width <= last; ++v) {
      const float y_over_z = (float(v) - cy) * inv_fy;
      const float* __restrict z = depth + v * width;
      for (std::size_t u = 0; u < width; ++u) {
        xs[u] = ax[u] * z[u];
        ys[u] = y_over_z * z[u];
      }
      const std::size_t end = std::min(width, last + 1 - v * width);
      // One 16-byte store per pixel (x, y, z, and a 4th float that the next point overwrites) while the slot
      // after this one is the block's too, then three floats.
      std::size_t u = 0;
#ifdef __SSE2__
      for (; u < end && n + 1 < limit; ++u) {
        _mm_storeu_ps(out + 3 * n, _mm_setr_ps(xs[u], ys[u], z[u], 0.0f));
        n += valid_depth(z[u]);
      }
#endif
      for (; u < end; ++u) {
        out[3 * n + 0] = xs[u];
        out[3 * n + 1] = ys[u];
        out[3 * n + 2] = z[u];
        n += valid_depth(z[u]);
      }
    }
    if (T_world_camera) {
      const Eigen::Index first = offset[size_t(b)];
      transform_points(R_W_C, t_W, out + 3 * first, points_W->data() + 3 * first, std::size_t(limit - first));
    }
  });
  return offset.back();
}

}  // namespace

Eigen::Index depth_to_cloud(const DepthImage& image, const CameraIntrinsics& intrinsics, Eigen::Matrix3Xf& points_C) {
  return cloud_of(image, intrinsics, points_C, nullptr, nullptr);
}

Eigen::Index depth_to_cloud(const DepthImage& image, const CameraIntrinsics& intrinsics, Eigen::Matrix3Xf& points_C,
                            const Eigen::Isometry3d& T_world_camera, Eigen::Matrix3Xf& points_W) {
  return cloud_of(image, intrinsics, points_C, &T_world_camera, &points_W);
}

Eigen::Matrix3Xf depth_to_cloud(const DepthImage& image, const CameraIntrinsics& intrinsics) {
  Eigen::Matrix3Xf buffer;
  const Eigen::Index n = depth_to_cloud(image, intrinsics, buffer);
  return buffer.leftCols(n);
}

std::vector<std::uint16_t> depth_to_millimetres(const DepthImage& image) {
  std::vector<std::uint16_t> mm(image.depth_m.size());
  for (size_t i = 0; i < image.depth_m.size(); ++i) {
    const float z = image.depth_m[i];
    mm[i] = static_cast<std::uint16_t>(
        (z > 0.0f && std::isfinite(z)) ? std::min(65535L, std::lround(double(z) * kMmPerMetre)) : 0L);
  }
  return mm;
}

void write_depth_png_mm(const DepthImage& image, const std::string& path) {
  check_image(image);
  write_png(path, image.width, image.height, PngFormat::kGray16, depth_to_millimetres(image).data(), 1);
}

void write_depth_png_colorized(const DepthImage& image, const std::string& path, double min_m, double max_m) {
  check_image(image);
  if (!(std::isfinite(min_m) && std::isfinite(max_m) && min_m < max_m)) {
    throw std::invalid_argument("write_depth_png_colorized: range [" + std::to_string(min_m) + ", " +
                                std::to_string(max_m) + "] must be finite with min < max");
  }
  const size_t row_bytes = size_t(image.width) * 3;
  std::vector<unsigned char> data(row_bytes * image.height, 0);
  for (size_t i = 0; i < image.depth_m.size(); ++i) {
    const float z = image.depth_m[i];
    if (z > 0.0f && std::isfinite(z)) turbo((z - min_m) / (max_m - min_m), &data[3 * i]);
  }
  write_png(path, image.width, image.height, PngFormat::kRgb8, data.data(), 1);
}

DepthImage read_depth_png_mm(const std::string& path) {
  const Gray16Image png = read_png_gray16(path);
  DepthImage image(png.width, png.height);
  for (size_t i = 0; i < png.pixels.size(); ++i) image.depth_m[i] = float(png.pixels[i]) * kMetresPerMmF;
  return image;
}

}  // namespace stvl::sensors

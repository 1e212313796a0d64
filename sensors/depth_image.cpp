#include "sensors/depth_image.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>

#include "common/png.hpp"

namespace stvl::sensors {
namespace {

void check_image(const DepthImage& image) {
  if (image.width <= 0 || image.height <= 0 || image.depth_m.size() != size_t(image.width) * image.height) {
    throw std::invalid_argument("DepthImage: size " + std::to_string(image.width) + "x" +
                                std::to_string(image.height) + " does not match " +
                                std::to_string(image.depth_m.size()) + " depth values");
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
  const double r = 0.13572138 + t * (4.61539260 + t * (-42.66032258 + t * (132.13108234 + t * (-152.94239396 + t * 59.28637943))));
  const double g = 0.09140261 + t * (2.19418839 + t * (4.84296658 + t * (-14.18503333 + t * (4.27729857 + t * 2.82956604))));
  const double b = 0.10667330 + t * (12.64194608 + t * (-60.58204836 + t * (110.36276771 + t * (-89.90310912 + t * 27.34824973))));
  rgb[0] = static_cast<unsigned char>(std::lround(255.0 * std::clamp(r, 0.0, 1.0)));
  rgb[1] = static_cast<unsigned char>(std::lround(255.0 * std::clamp(g, 0.0, 1.0)));
  rgb[2] = static_cast<unsigned char>(std::lround(255.0 * std::clamp(b, 0.0, 1.0)));
}

}  // namespace

int DepthImage::valid_count() const {
  return int(std::count_if(depth_m.begin(), depth_m.end(), [](float z) { return z > 0.0f && std::isfinite(z); }));
}

Eigen::Index depth_to_cloud(const DepthImage& image, const CameraIntrinsics& intrinsics, Eigen::Matrix3Xf& points_C) {
  check_matches(image, intrinsics);
  const Eigen::Index n_pixels = Eigen::Index(image.width) * image.height;
  if (points_C.cols() < n_pixels) points_C.resize(3, n_pixels);
  const float inv_fx = float(1.0 / intrinsics.fx), inv_fy = float(1.0 / intrinsics.fy);
  const float cx = float(intrinsics.cx), cy = float(intrinsics.cy);
  float* out = points_C.data();
  const float* depth = image.depth_m.data();
  const auto valid = [](float z) { return z > 0.0f && std::isfinite(z); };
  // Two passes over blocks of rows in parallel (TBB): count each block's valid pixels, then write each block's
  // points from its offset, so that the points keep row-major pixel order whatever the threads.
  constexpr int kRowsPerBlock = 16;
  const int blocks = (image.height + kRowsPerBlock - 1) / kRowsPerBlock;
  std::vector<Eigen::Index> offset(size_t(blocks) + 1, 0);
  tbb::parallel_for(0, blocks, [&](int b) {
    const float* row = depth + size_t(b) * kRowsPerBlock * image.width;
    const float* end = depth + size_t(std::min(image.height, (b + 1) * kRowsPerBlock)) * image.width;
    offset[size_t(b) + 1] = std::count_if(row, end, valid);
  });
  for (int b = 0; b < blocks; ++b) offset[size_t(b) + 1] += offset[size_t(b)];
  tbb::parallel_for(0, blocks, [&](int b) {
    Eigen::Index n = offset[size_t(b)];
    for (int v = b * kRowsPerBlock; v < std::min(image.height, (b + 1) * kRowsPerBlock); ++v) {
      const float y_over_z = (float(v) - cy) * inv_fy;
      for (int u = 0; u < image.width; ++u) {
        const float z = depth[size_t(v) * image.width + u];
        if (!valid(z)) continue;
        out[3 * n + 0] = (float(u) - cx) * inv_fx * z;
        out[3 * n + 1] = y_over_z * z;
        out[3 * n + 2] = z;
        ++n;
      }
    }
  });
  return offset.back();
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
    mm[i] = static_cast<std::uint16_t>((z > 0.0f && std::isfinite(z)) ? std::min(65535L, std::lround(double(z) * 1000.0)) : 0L);
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
  for (size_t i = 0; i < png.pixels.size(); ++i) image.depth_m[i] = float(png.pixels[i]) * 0.001f;
  return image;
}

}  // namespace stvl::sensors

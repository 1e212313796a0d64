#include "sensors/depth_image.hpp"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>

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

// rows: height pointers to rows of bytes; bit_depth 8 (RGB) or 16 (grey, host order converted here).
void write_png(const std::string& path, int width, int height, int bit_depth, int color_type,
               const std::vector<unsigned char>& data, size_t row_bytes) {
  const std::string tmp = path + ".tmp";
  FILE* file = std::fopen(tmp.c_str(), "wb");
  if (!file) throw std::runtime_error("cannot open " + tmp + " for writing");
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(file);
    std::remove(tmp.c_str());
    throw std::runtime_error("libpng failed writing " + tmp);
  }
  png_init_io(png, file);
  png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), bit_depth, color_type, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, 1);
  png_write_info(png, info);
  for (int v = 0; v < height; ++v) png_write_row(png, const_cast<png_bytep>(data.data() + size_t(v) * row_bytes));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  const bool write_failed = std::ferror(file) != 0;
  if (std::fclose(file) != 0 || write_failed) {
    std::remove(tmp.c_str());
    throw std::runtime_error("write error on " + tmp);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot rename " + tmp + " to " + path);
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
  Eigen::Index n = 0;
  for (int v = 0; v < image.height; ++v) {
    const float y_over_z = (float(v) - cy) * inv_fy;
    for (int u = 0; u < image.width; ++u) {
      const float z = depth[size_t(v) * image.width + u];
      if (!(z > 0.0f) || !std::isfinite(z)) continue;
      out[3 * n + 0] = (float(u) - cx) * inv_fx * z;
      out[3 * n + 1] = y_over_z * z;
      out[3 * n + 2] = z;
      ++n;
    }
  }
  return n;
}

Eigen::Matrix3Xf depth_to_cloud(const DepthImage& image, const CameraIntrinsics& intrinsics) {
  Eigen::Matrix3Xf buffer;
  const Eigen::Index n = depth_to_cloud(image, intrinsics, buffer);
  return buffer.leftCols(n);
}

void write_depth_png_mm(const DepthImage& image, const std::string& path) {
  check_image(image);
  const size_t row_bytes = size_t(image.width) * 2;
  std::vector<unsigned char> data(row_bytes * image.height);
  for (size_t i = 0; i < image.depth_m.size(); ++i) {
    const float z = image.depth_m[i];
    const long mm = (z > 0.0f && std::isfinite(z)) ? std::min(65535L, std::lround(double(z) * 1000.0)) : 0L;
    data[2 * i] = static_cast<unsigned char>(mm >> 8);  // PNG stores 16-bit samples big-endian
    data[2 * i + 1] = static_cast<unsigned char>(mm & 0xff);
  }
  write_png(path, image.width, image.height, 16, PNG_COLOR_TYPE_GRAY, data, row_bytes);
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
  write_png(path, image.width, image.height, 8, PNG_COLOR_TYPE_RGB, data, row_bytes);
}

DepthImage read_depth_png_mm(const std::string& path) {
  FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) throw std::runtime_error("cannot open " + path);
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info || setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    std::fclose(file);
    throw std::runtime_error("libpng failed reading " + path);
  }
  png_init_io(png, file);
  png_read_info(png, info);
  if (png_get_bit_depth(png, info) != 16 || png_get_color_type(png, info) != PNG_COLOR_TYPE_GRAY) {
    png_destroy_read_struct(&png, &info, nullptr);
    std::fclose(file);
    throw std::runtime_error(path + " is not a 16-bit grey PNG");
  }
  DepthImage image(int(png_get_image_width(png, info)), int(png_get_image_height(png, info)));
  std::vector<unsigned char> row(size_t(image.width) * 2);
  for (int v = 0; v < image.height; ++v) {
    png_read_row(png, row.data(), nullptr);
    for (int u = 0; u < image.width; ++u) image.at(u, v) = float((row[2 * u] << 8) | row[2 * u + 1]) * 0.001f;
  }
  png_destroy_read_struct(&png, &info, nullptr);
  std::fclose(file);
  return image;
}

}  // namespace stvl::sensors

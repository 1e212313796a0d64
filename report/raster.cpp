#include "report/raster.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "common/atomic_file.hpp"
#include "common/png.hpp"

namespace stvl::report {

RgbImage::RgbImage(int width, int height, Rgb background) : width_(width), height_(height) {
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384)
    throw std::invalid_argument("image size " + std::to_string(width) + "x" + std::to_string(height) +
                                " is out of range (1..16384)");
  rgb_.resize(static_cast<std::size_t>(width) * height * 3);
  for (std::size_t i = 0; i < rgb_.size(); i += 3) std::copy(background.begin(), background.end(), &rgb_[i]);
}

void RgbImage::set(int x, int y, Rgb color) {
  if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
  std::copy(color.begin(), color.end(), &rgb_[(static_cast<std::size_t>(y) * width_ + x) * 3]);
}

Rgb RgbImage::at(int x, int y) const {
  const auto* p = &rgb_[(static_cast<std::size_t>(y) * width_ + x) * 3];
  return {p[0], p[1], p[2]};
}

void RgbImage::fill_rect(int x0, int y0, int x1, int y1, Rgb color) {
  for (int y = std::max(0, std::min(y0, y1)); y <= std::min(height_ - 1, std::max(y0, y1)); ++y)
    for (int x = std::max(0, std::min(x0, x1)); x <= std::min(width_ - 1, std::max(x0, x1)); ++x) set(x, y, color);
}

void RgbImage::line(int x0, int y0, int x1, int y1, Rgb color) {
  // Clip the segment to the image first (Liang-Barsky), so that Bresenham walks only pixels inside it.
  const double dx = double(x1) - x0, dy = double(y1) - y0;
  double t0 = 0.0, t1 = 1.0;
  const auto clip = [&](double p, double q) {  // keeps the part where p * t <= q
    if (p == 0.0) return q >= 0.0;
    const double t = q / p;
    if (p < 0.0) t0 = std::max(t0, t);
    else t1 = std::min(t1, t);
    return t0 <= t1;
  };
  if (!clip(-dx, x0) || !clip(dx, width_ - 1.0 - x0) || !clip(-dy, y0) || !clip(dy, height_ - 1.0 - y0)) return;
  int ax = static_cast<int>(std::lround(x0 + t0 * dx)), ay = static_cast<int>(std::lround(y0 + t0 * dy));
  const int bx = static_cast<int>(std::lround(x0 + t1 * dx)), by = static_cast<int>(std::lround(y0 + t1 * dy));
  const int step_x = ax < bx ? 1 : -1, step_y = ay < by ? 1 : -1;
  const int adx = std::abs(bx - ax), ady = -std::abs(by - ay);
  int error = adx + ady;
  while (true) {
    set(ax, ay, color);
    if (ax == bx && ay == by) break;
    const int e2 = 2 * error;
    if (e2 >= ady) error += ady, ax += step_x;
    if (e2 <= adx) error += adx, ay += step_y;
  }
}

std::string encode_png(const RgbImage& image) {
  return stvl::encode_png(image.width(), image.height(), PngFormat::kRgb8, image.rgb().data());
}

void write_png(const std::filesystem::path& path, const RgbImage& image) {
  write_file_atomically(path, encode_png(image));
}

}  // namespace stvl::report

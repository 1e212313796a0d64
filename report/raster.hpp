#pragma once
// A small RGB raster for the report's pictures (top-down maps, paths, timing plots), saved as PNG.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace stvl::report {

using Rgb = std::array<std::uint8_t, 3>;

class RgbImage {
 public:
  RgbImage(int width, int height, Rgb background = {255, 255, 255});
  int width() const { return width_; }
  int height() const { return height_; }
  // Pixels outside the image are ignored, so callers can draw without clipping.
  void set(int x, int y, Rgb color);
  Rgb at(int x, int y) const;
  void fill_rect(int x0, int y0, int x1, int y1, Rgb color);
  void line(int x0, int y0, int x1, int y1, Rgb color);
  const std::vector<std::uint8_t>& rgb() const { return rgb_; }

 private:
  int width_;
  int height_;
  std::vector<std::uint8_t> rgb_;
};

// Encodes as an 8-bit RGB PNG.
std::string encode_png(const RgbImage& image);
// Writes atomically (temporary name, then rename).
void write_png(const std::filesystem::path& path, const RgbImage& image);

}  // namespace stvl::report

#pragma once
// PNG encoding and decoding (libpng), the one place the project touches libpng.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace stvl {

enum class PngFormat {
  kGray16,  // one std::uint16_t per pixel (host order; PNG stores it big-endian)
  kRgb8,    // three std::uint8_t per pixel
};

// Encodes width x height pixels, row-major, top row first. compression_level: zlib's 0..9, -1 its default.
// Throws std::invalid_argument for sizes outside 1..65535, std::runtime_error when libpng fails.
std::string encode_png(int width, int height, PngFormat format, const void* pixels, int compression_level = -1);

// encode_png written atomically (temporary name, then rename); throws std::runtime_error naming the path.
void write_png(const std::filesystem::path& path, int width, int height, PngFormat format, const void* pixels,
               int compression_level = -1);

struct Gray16Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint16_t> pixels;  // row-major, top row first
};

// Reads a 16-bit greyscale PNG; throws std::runtime_error naming the path when it cannot be read or is another
// kind of PNG.
Gray16Image read_png_gray16(const std::filesystem::path& path);

}  // namespace stvl

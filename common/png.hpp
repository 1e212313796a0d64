#pragma once
// PNG encoding and decoding (libpng), the one place the project touches libpng.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace stvl {

enum class PngFormat {
  kGray16,      // one std::uint16_t per pixel (host order; PNG stores it big-endian)
  kRgb8,        // three std::uint8_t per pixel
  kGray8,       // one std::uint8_t per pixel
  kGrayAlpha8,  // two std::uint8_t per pixel: grey, alpha
  kRgba8,       // four std::uint8_t per pixel
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

// Any PNG decoded to its samples: palettes become RGB, a tRNS chunk an alpha channel, grey below 8 bits is
// scaled to 8 bits (1-bit 1 -> 255); 8- and 16-bit samples are kept as they are.
struct PngImage {
  int width = 0;
  int height = 0;
  int channels = 0;                    // 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA
  int bit_depth = 0;                   // 8 or 16: samples lie in 0 .. 2^bit_depth - 1
  std::vector<std::uint16_t> samples;  // row-major, top row first, `channels` samples per pixel
};

// Decodes PNG bytes. Throws std::runtime_error naming `name` when the bytes are no PNG, are truncated or corrupt,
// or when width x height exceeds max_pixels (checked from the header, before the pixels are allocated).
PngImage decode_png(const std::string& bytes, const std::string& name, std::size_t max_pixels);

}  // namespace stvl

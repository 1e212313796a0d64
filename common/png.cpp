#include "common/png.hpp"

#include <png.h>

#include <cstdio>
#include <memory>
#include <stdexcept>

#include "common/atomic_file.hpp"

namespace stvl {
namespace {

void append_to_string(png_structp png, png_bytep data, png_size_t length) {
  static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<const char*>(data), length);
}

}  // namespace

std::string encode_png(int width, int height, PngFormat format, const void* pixels, int compression_level) {
  if (width < 1 || height < 1 || width > 65535 || height > 65535)
    throw std::invalid_argument("PNG size " + std::to_string(width) + "x" + std::to_string(height) +
                                " is out of range (1..65535)");
  const bool gray16 = format == PngFormat::kGray16;
  const std::size_t row_bytes = static_cast<std::size_t>(width) * (gray16 ? 2 : 3);
  // libpng wants 16-bit samples big-endian.
  std::vector<unsigned char> row(row_bytes);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    throw std::runtime_error("libpng: cannot allocate the encoder");
  }
  std::string bytes;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error("libpng: encoding failed");
  }
  png_set_write_fn(png, &bytes, append_to_string, nullptr);
  png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), gray16 ? 16 : 8,
               gray16 ? PNG_COLOR_TYPE_GRAY : PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  if (compression_level >= 0) png_set_compression_level(png, compression_level);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y) {
    if (gray16) {
      const auto* in = static_cast<const std::uint16_t*>(pixels) + static_cast<std::size_t>(y) * width;
      for (int x = 0; x < width; ++x) {
        row[2 * x] = static_cast<unsigned char>(in[x] >> 8);
        row[2 * x + 1] = static_cast<unsigned char>(in[x] & 0xff);
      }
      png_write_row(png, row.data());
    } else {
      png_write_row(png, const_cast<png_bytep>(static_cast<const unsigned char*>(pixels) + y * row_bytes));
    }
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return bytes;
}

void write_png(const std::filesystem::path& path, int width, int height, PngFormat format, const void* pixels,
               int compression_level) {
  write_file_atomically(path, encode_png(width, height, format, pixels, compression_level));
}

Gray16Image read_png_gray16(const std::filesystem::path& path) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file) throw std::runtime_error("cannot open " + path.string());
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info || setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw std::runtime_error("libpng failed reading " + path.string());
  }
  png_init_io(png, file.get());
  png_read_info(png, info);
  if (png_get_bit_depth(png, info) != 16 || png_get_color_type(png, info) != PNG_COLOR_TYPE_GRAY) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw std::runtime_error(path.string() + " is not a 16-bit grey PNG");
  }
  Gray16Image image;
  image.width = static_cast<int>(png_get_image_width(png, info));
  image.height = static_cast<int>(png_get_image_height(png, info));
  image.pixels.resize(static_cast<std::size_t>(image.width) * image.height);
  std::vector<unsigned char> row(static_cast<std::size_t>(image.width) * 2);
  for (int y = 0; y < image.height; ++y) {
    png_read_row(png, row.data(), nullptr);
    for (int x = 0; x < image.width; ++x)
      image.pixels[static_cast<std::size_t>(y) * image.width + x] =
          static_cast<std::uint16_t>((row[2 * x] << 8) | row[2 * x + 1]);
  }
  png_destroy_read_struct(&png, &info, nullptr);
  return image;
}

}  // namespace stvl

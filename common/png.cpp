#include "common/png.hpp"

#include <png.h>

#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>

#include "common/atomic_file.hpp"

namespace stvl {
namespace {

void append_to_string(png_structp png, png_bytep data, png_size_t length) {
  static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<const char*>(data), length);
}

int samples_per_pixel(PngFormat format) {
  switch (format) {
    case PngFormat::kGray16:
    case PngFormat::kGray8: return 1;
    case PngFormat::kGrayAlpha8: return 2;
    case PngFormat::kRgb8: return 3;
    case PngFormat::kRgba8: return 4;
  }
  return 1;
}

int color_type(PngFormat format) {
  switch (format) {
    case PngFormat::kGray16:
    case PngFormat::kGray8: return PNG_COLOR_TYPE_GRAY;
    case PngFormat::kGrayAlpha8: return PNG_COLOR_TYPE_GRAY_ALPHA;
    case PngFormat::kRgb8: return PNG_COLOR_TYPE_RGB;
    case PngFormat::kRgba8: return PNG_COLOR_TYPE_RGB_ALPHA;
  }
  return PNG_COLOR_TYPE_GRAY;
}

// Bytes being decoded; a read past their end is a truncated file.
struct MemoryReader {
  const std::string* bytes;
  std::size_t at;
};

void read_from_memory(png_structp png, png_bytep data, png_size_t length) {
  auto* reader = static_cast<MemoryReader*>(png_get_io_ptr(png));
  if (reader->bytes->size() - reader->at < length) png_error(png, "the file ends early (truncated)");
  std::memcpy(data, reader->bytes->data() + reader->at, length);
  reader->at += length;
}

// libpng's message kept for the exception thrown after its longjmp.
void keep_error(png_structp png, png_const_charp message) {
  *static_cast<std::string*>(png_get_error_ptr(png)) = message;
  png_longjmp(png, 1);
}
void ignore_warning(png_structp, png_const_charp) {}

}  // namespace

std::string encode_png(int width, int height, PngFormat format, const void* pixels, int compression_level) {
  if (width < 1 || height < 1 || width > 65535 || height > 65535)
    throw std::invalid_argument("PNG size " + std::to_string(width) + "x" + std::to_string(height) +
                                " is out of range (1..65535)");
  const bool gray16 = format == PngFormat::kGray16;
  const std::size_t row_bytes = static_cast<std::size_t>(width) * (gray16 ? 2 : samples_per_pixel(format));
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
  png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), gray16 ? 16 : 8, color_type(format),
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
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

PngImage decode_png(const std::string& bytes, const std::string& name, std::size_t max_pixels) {
  if (bytes.size() < 8 || png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) != 0)
    throw std::runtime_error(name + ": not a PNG file (no PNG signature)");
  // Everything that lives across libpng's longjmp is declared before setjmp.
  PngImage image;
  std::vector<png_bytep> rows;
  std::string error, pixels;
  volatile bool too_large = false;
  MemoryReader reader{&bytes, 0};
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &error, keep_error, ignore_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw std::runtime_error("libpng: cannot allocate the decoder");
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    if (too_large) throw std::runtime_error(error);
    throw std::runtime_error(name + ": corrupt PNG (" + error + ")");
  }
  png_set_read_fn(png, &reader, read_from_memory);
  png_read_info(png, info);
  const png_uint_32 width = png_get_image_width(png, info), height = png_get_image_height(png, info);
  if (static_cast<double>(width) * height > static_cast<double>(max_pixels)) {
    too_large = true;
    error = name + ": " + std::to_string(width) + " x " + std::to_string(height) + " pixels exceed the limit of " +
            std::to_string(max_pixels);
    png_longjmp(png, 1);
  }
  const int type = png_get_color_type(png, info);
  if (type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (type == PNG_COLOR_TYPE_GRAY && png_get_bit_depth(png, info) < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  image.width = static_cast<int>(width);
  image.height = static_cast<int>(height);
  image.channels = png_get_channels(png, info);
  image.bit_depth = png_get_bit_depth(png, info);
  const std::size_t row_bytes = png_get_rowbytes(png, info);
  pixels.assign(row_bytes * height, '\0');
  rows.resize(height);
  for (png_uint_32 y = 0; y < height; ++y) rows[y] = reinterpret_cast<png_bytep>(&pixels[y * row_bytes]);
  png_read_image(png, rows.data());
  png_destroy_read_struct(&png, &info, nullptr);
  const std::size_t count = static_cast<std::size_t>(width) * height * image.channels;
  image.samples.resize(count);
  const auto* p = reinterpret_cast<const unsigned char*>(pixels.data());
  for (png_uint_32 y = 0; y < height; ++y) {
    const unsigned char* row = p + y * row_bytes;
    std::uint16_t* out = image.samples.data() + static_cast<std::size_t>(y) * width * image.channels;
    for (std::size_t i = 0; i < static_cast<std::size_t>(width) * image.channels; ++i)
      out[i] = image.bit_depth == 16 ? static_cast<std::uint16_t>((row[2 * i] << 8) | row[2 * i + 1]) : row[i];
  }
  return image;
}

}  // namespace stvl

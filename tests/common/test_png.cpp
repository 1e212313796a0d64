#include "common/png.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace stvl {
namespace {

namespace fs = std::filesystem;

TEST(Png, Gray16RoundTripKeepsEverySample) {
  const int width = 7, height = 3;
  std::vector<std::uint16_t> pixels(width * height);
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<std::uint16_t>(i * 3001 + (i % 2) * 255);
  pixels.back() = 65535;
  const fs::path path = fs::temp_directory_path() / ("stvl_png_" + std::to_string(::getpid()) + ".png");
  write_png(path, width, height, PngFormat::kGray16, pixels.data(), 1);
  const Gray16Image back = read_png_gray16(path);
  fs::remove(path);
  EXPECT_EQ(back.width, width);
  EXPECT_EQ(back.height, height);
  EXPECT_EQ(back.pixels, pixels);
}

TEST(Png, Rgb8StartsWithThePngSignatureAndIsNotGray16) {
  const std::vector<std::uint8_t> rgb(4 * 2 * 3, 128);
  const std::string bytes = encode_png(4, 2, PngFormat::kRgb8, rgb.data());
  ASSERT_GT(bytes.size(), 8u);
  EXPECT_EQ(bytes.substr(1, 3), "PNG");
  const fs::path path = fs::temp_directory_path() / ("stvl_png_rgb_" + std::to_string(::getpid()) + ".png");
  write_png(path, 4, 2, PngFormat::kRgb8, rgb.data());
  EXPECT_THROW(read_png_gray16(path), std::runtime_error);
  fs::remove(path);
}

TEST(Png, BadSizesAndMissingFilesThrow) {
  const std::uint16_t pixel = 0;
  EXPECT_THROW(encode_png(0, 1, PngFormat::kGray16, &pixel), std::invalid_argument);
  EXPECT_THROW(encode_png(1, 70000, PngFormat::kGray16, &pixel), std::invalid_argument);
  EXPECT_THROW(read_png_gray16("/nonexistent/stvl.png"), std::runtime_error);
}

}  // namespace
}  // namespace stvl

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

TEST(Png, DecodeGivesTheSamplesOfEveryColourType) {
  const std::vector<std::uint8_t> grey_alpha{0, 255, 128, 7, 254, 0};
  const PngImage ga = decode_png(encode_png(3, 1, PngFormat::kGrayAlpha8, grey_alpha.data()), "ga.png", 100);
  EXPECT_EQ(ga.width, 3);
  EXPECT_EQ(ga.height, 1);
  EXPECT_EQ(ga.channels, 2);
  EXPECT_EQ(ga.bit_depth, 8);
  EXPECT_EQ(ga.samples, std::vector<std::uint16_t>(grey_alpha.begin(), grey_alpha.end()));
  const std::vector<std::uint8_t> rgba{1, 2, 3, 4, 5, 6, 7, 8};
  const PngImage c = decode_png(encode_png(1, 2, PngFormat::kRgba8, rgba.data()), "c.png", 100);
  EXPECT_EQ(c.channels, 4);
  EXPECT_EQ(c.samples, std::vector<std::uint16_t>(rgba.begin(), rgba.end()));
  const std::vector<std::uint16_t> deep{0, 65535, 300};
  const PngImage d = decode_png(encode_png(3, 1, PngFormat::kGray16, deep.data()), "d.png", 100);
  EXPECT_EQ(d.bit_depth, 16);
  EXPECT_EQ(d.samples, deep);
}

TEST(Png, DecodeRefusesTruncatedAndOversizedImagesNamingThem) {
  const std::vector<std::uint8_t> grey(64 * 64, 9);
  const std::string bytes = encode_png(64, 64, PngFormat::kGray8, grey.data());
  EXPECT_THROW(decode_png(bytes.substr(0, bytes.size() / 2), "half.png", 1 << 20), std::runtime_error);
  try {
    decode_png(bytes, "big.png", 4095);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("big.png: 64 x 64 pixels exceed the limit of 4095"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(decode_png("not a png", "x.png", 100), std::runtime_error);
}

}  // namespace
}  // namespace stvl

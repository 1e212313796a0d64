// The nav2 map reader against map_server's formula (nav2_map_server map_io.cpp) on hand-computed pixels, every
// image kind it reads, and the errors for malformed maps.
#include "worldgen/nav2_map.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/png.hpp"
#include "tests/support/invalid_argument.hpp"
#include "tests/worldgen/helpers.hpp"

namespace stvl::worldgen {
namespace {

using test::map_yaml;
using test::pgm_p5;
using test::TempDir;
using ::testing::HasSubstr;

MapMetadata meta(MapMode mode, bool negate = false, double occupied = 0.65, double free = 0.196) {
  MapMetadata m;
  m.resolution_m = 0.1;
  m.mode = mode;
  m.negate = negate;
  m.occupied_thresh = occupied;
  m.free_thresh = free;
  return m;
}

// The occupancy values of a one-row image, left to right.
std::vector<int> row_values(const std::string& bytes, const MapMetadata& m) {
  const Nav2Map map = to_occupancy(decode_map_image(bytes, "test"), m);
  std::vector<int> out;
  for (int x = 0; x < map.width; ++x) out.push_back(map.at(x, 0));
  return out;
}

std::string png(int width, int height, PngFormat format, const std::vector<std::uint8_t>& samples) {
  return encode_png(width, height, format, samples.data());
}

TEST(Nav2Map, TrinaryP5FollowsMapServerOnHandComputedPixels) {
  // occ = 1 - v / 255: 0 -> 1.0 (occupied), 89 -> 0.651 (> 0.65, occupied), 90 -> 0.647 (unknown),
  // 205 -> 0.19608 (not below 0.196: unknown, map_saver's grey), 254 -> 0.0039 (free).
  EXPECT_EQ(row_values(pgm_p5(5, 1, {0, 89, 90, 205, 254}), meta(MapMode::kTrinary)),
            (std::vector<int>{100, 100, -1, -1, 0}));
}

TEST(Nav2Map, NegateSwapsWhatIsOccupiedButNotTheThresholds) {
  // negate: occ = shade; 0 -> 0 (free), 254 -> 0.996 (occupied), 205 -> 0.804 (occupied).
  EXPECT_EQ(row_values(pgm_p5(3, 1, {0, 254, 205}), meta(MapMode::kTrinary, true)), (std::vector<int>{0, 100, 100}));
}

TEST(Nav2Map, ScaleModeInterpolatesBetweenTheThresholds) {
  // free 0.25, occupied 0.65: 128 -> occ 0.49804 -> rint(62.01) = 62; 150 -> 0.41176 -> rint(40.44) = 40;
  // 200 -> 0.2157 (free), 60 -> 0.7647 (occupied).
  EXPECT_EQ(row_values(pgm_p5(4, 1, {128, 150, 200, 60}), meta(MapMode::kScale, false, 0.65, 0.25)),
            (std::vector<int>{62, 40, 0, 100}));
}

TEST(Nav2Map, RawModeIsThePixelValueUpTo100) {
  // round(shade * 255): the 8-bit value itself, -1 above 100; negate and the thresholds are not used.
  const std::string bytes = pgm_p5(5, 1, {0, 37, 100, 101, 255});
  EXPECT_EQ(row_values(bytes, meta(MapMode::kRaw)), (std::vector<int>{0, 37, 100, -1, -1}));
  EXPECT_EQ(row_values(bytes, meta(MapMode::kRaw, true, 0.9, 0.1)), (std::vector<int>{0, 37, 100, -1, -1}));
}

TEST(Nav2Map, SixteenBitP5ScalesByItsMaxval) {
  // 16-bit big-endian samples: 0 -> occupied, 32768 -> shade 0.5 (unknown), 65535 -> free, 12850 (50 * 257) ->
  // occ 0.804 (occupied); raw mode: 12850 -> round(0.19608 * 255) = 50.
  const std::string bytes = pgm_p5(4, 1, {0, 32768, 65535, 12850}, 65535);
  EXPECT_EQ(row_values(bytes, meta(MapMode::kTrinary)), (std::vector<int>{100, -1, 0, 100}));
  EXPECT_EQ(row_values(bytes, meta(MapMode::kRaw)).back(), 50);
}

TEST(Nav2Map, PlainP2WithCommentsAndAnyMaxval) {
  const std::string bytes =
      "P2\n# CREATOR: hand\n3 1 # width height\n# maxval next\n100\n0 50\n# in the raster too\n100\n";
  EXPECT_EQ(row_values(bytes, meta(MapMode::kTrinary)), (std::vector<int>{100, -1, 0}));
}

TEST(Nav2Map, ImageTopRowIsTheMapsLastRow) {
  const Nav2Map map = to_occupancy(decode_map_image(pgm_p5(2, 2, {0, 254, 254, 254}), "test"), meta(MapMode::kTrinary));
  EXPECT_EQ(map.at(0, 1), 100);  // top-left pixel: column 0 of the top map row
  EXPECT_EQ(map.at(0, 0), 0);
  EXPECT_EQ(map.at(1, 1), 0);
}

TEST(Nav2Map, PngGreyRgbAndAlphaAsMapServerAveragesThem) {
  EXPECT_EQ(row_values(png(3, 1, PngFormat::kGray8, {0, 205, 254}), meta(MapMode::kTrinary)),
            (std::vector<int>{100, -1, 0}));
  // RGB: the mean of the channels. (255, 0, 0) -> 85 -> occ 0.667 (occupied); (255, 255, 0) -> 170 -> 0.333
  // (unknown); (200, 250, 254) -> 234.67 -> 0.080 (free).
  EXPECT_EQ(row_values(png(3, 1, PngFormat::kRgb8, {255, 0, 0, 255, 255, 0, 200, 250, 254}), meta(MapMode::kTrinary)),
            (std::vector<int>{100, -1, 0}));
  // Trinary with alpha: the alpha joins the mean as a fourth channel. (254, a 255) -> 254.25 -> free;
  // (254, a 0) -> 190.5 -> occ 0.2529 (unknown); (0, a 0) -> occupied.
  const std::string grey_alpha = png(3, 1, PngFormat::kGrayAlpha8, {254, 255, 254, 0, 0, 0});
  EXPECT_EQ(row_values(grey_alpha, meta(MapMode::kTrinary)), (std::vector<int>{0, -1, 100}));
  // Scale: a pixel that is not opaque is unknown; an opaque one uses the colour only. (128, a 255) -> 62.
  const std::string scale_alpha = png(2, 1, PngFormat::kGrayAlpha8, {128, 255, 128, 254});
  EXPECT_EQ(row_values(scale_alpha, meta(MapMode::kScale, false, 0.65, 0.25)), (std::vector<int>{62, -1}));
  // RGBA in raw mode: the colour's mean, alpha ignored.
  EXPECT_EQ(row_values(png(1, 1, PngFormat::kRgba8, {30, 40, 50, 7}), meta(MapMode::kRaw)), (std::vector<int>{40}));
}

TEST(Nav2Map, SixteenBitPngKeepsItsSamples) {
  const std::vector<std::uint16_t> pixels{0, 65535};
  const std::string bytes = encode_png(2, 1, PngFormat::kGray16, pixels.data());
  EXPECT_EQ(row_values(bytes, meta(MapMode::kTrinary)), (std::vector<int>{100, 0}));
}

TEST(Nav2Map, LoadsTheYamlAndAnImageBesideIt) {
  TempDir dir;
  dir.write("floor.pgm", pgm_p5(3, 2, {0, 254, 205, 254, 254, 254}));
  const std::string yaml = dir.write("floor.yaml", map_yaml("floor.pgm", 0.05, "[-1.5, 2.0, 0.25]") + "# a comment\n");
  const Nav2Map map = load_nav2_map(yaml);
  EXPECT_EQ(map.width, 3);
  EXPECT_EQ(map.height, 2);
  EXPECT_DOUBLE_EQ(map.meta.resolution_m, 0.05);
  EXPECT_DOUBLE_EQ(map.meta.origin_x_m, -1.5);
  EXPECT_DOUBLE_EQ(map.meta.origin_y_m, 2.0);
  EXPECT_DOUBLE_EQ(map.meta.origin_yaw_rad, 0.25);
  EXPECT_EQ(map.meta.mode, MapMode::kTrinary);
  EXPECT_EQ(map.meta.image_path, (dir.path() / "floor.pgm").string());
  EXPECT_EQ(map.at(0, 1), 100);
  EXPECT_EQ(map.at(2, 1), -1);
}

TEST(Nav2Map, ModeDefaultsToTrinaryAndNegateMayBeABoolean) {
  const MapMetadata m = parse_map_yaml(map_yaml("a.pgm", 0.05, "[0, 0, 0]", 0, 0.65, 0.196, ""), "m.yaml", "/maps");
  EXPECT_EQ(m.mode, MapMode::kTrinary);
  EXPECT_EQ(m.image_path, "/maps/a.pgm");
  const std::string yes =
      "image: /abs/a.png\nresolution: 1\norigin: [0, 0, 0]\nnegate: true\noccupied_thresh: 0.6\nfree_thresh: 0.2\n";
  EXPECT_TRUE(parse_map_yaml(yes, "m.yaml", "/maps").negate);
  EXPECT_EQ(parse_map_yaml(yes, "m.yaml", "/maps").image_path, "/abs/a.png");
}

TEST(Nav2MapErrors, YamlKeysAndValuesNameTheFileLineAndFix) {
  const auto parse = [](const std::string& text) {
    return stvl::test::invalid_argument_of([&] { parse_map_yaml(text, "map.yaml", "/m"); });
  };
  const std::string good = map_yaml("a.pgm");
  EXPECT_THAT(parse(good + "resolutoin: 0.05\n"),
              HasSubstr("map.yaml:8: resolutoin: unknown key; did you mean 'resolution'?"));
  EXPECT_THAT(parse(map_yaml("a.pgm", 0.0)), HasSubstr("map.yaml:2: resolution: must be a finite number in (0, 100]"));
  EXPECT_THAT(parse(map_yaml("a.pgm", -0.05)), HasSubstr("resolution: must be a finite number"));
  EXPECT_THAT(
      parse("image: a.pgm\nresolution: .nan\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.2\n"),
      HasSubstr("resolution: must be a finite number"));
  EXPECT_THAT(parse(map_yaml("a.pgm", 0.05, "[.nan, 0, 0]")), HasSubstr("map.yaml:3: origin: x and y must be finite"));
  EXPECT_THAT(parse(map_yaml("a.pgm", 0.05, "[0, 0]")), HasSubstr("origin: expected [x, y, yaw]"));
  EXPECT_THAT(parse(map_yaml("a.pgm", 0.05, "[0, 0, 0]", 0, 0.65, 0.196, "trinery")),
              HasSubstr("did you mean 'trinary'?"));
  EXPECT_THAT(parse(map_yaml("a.pgm", 0.05, "[0, 0, 0]", 0, 0.3, 0.5)),
              HasSubstr("free_thresh: must lie in [0, occupied_thresh)"));
  EXPECT_THAT(parse(map_yaml("a.pgm", 0.05, "[0, 0, 0]", 0, 1.5, 0.2)),
              HasSubstr("occupied_thresh: must lie in (0, 1]"));
  EXPECT_THAT(parse("image: a.pgm\nresolution: 0.05\norigin: [0, 0, 0]\noccupied_thresh: 0.65\nfree_thresh: 0.2\n"),
              HasSubstr("negate: required key is missing"));
  EXPECT_THAT(parse(good + "negate: 1\n"), HasSubstr("negate: duplicate key"));
  EXPECT_THAT(parse("image: [a\n"), HasSubstr("map.yaml:1: malformed YAML"));
  EXPECT_THAT(parse("- a\n- b\n"), HasSubstr("expected map_server's keys"));
  EXPECT_THAT(parse(map_yaml("a.pgm", 0.05, "[0, 0, 0]", 0) + "negatee: 1\n"), HasSubstr("did you mean 'negate'?"));
}

TEST(Nav2MapErrors, ImagesNameTheFileAndWhatIsWrong) {
  const auto decode = [](const std::string& bytes) {
    return stvl::test::invalid_argument_of([&] { decode_map_image(bytes, "img.pgm"); });
  };
  EXPECT_THAT(decode("GIF89a..."), HasSubstr("img.pgm: not a PGM (P5 or P2) or PNG image (it starts 'GI')"));
  EXPECT_THAT(decode("P6\n1 1\n255\nabc"), HasSubstr("not a PGM"));
  EXPECT_THAT(decode(pgm_p5(4, 4, std::vector<int>(16, 0)).substr(0, 40)), HasSubstr("the PGM ends after"));
  EXPECT_THAT(decode("P2\n3 1\n255\n0 1\n"), HasSubstr("ends before its pixel 2 of 3 (truncated)"));
  EXPECT_THAT(decode("P5\n2 1\n0\n\x01\x01"), HasSubstr("maxval 0 is outside 1..65535"));
  EXPECT_THAT(decode("P5\n2 1\n70000\n"), HasSubstr("maxval 70000 is outside"));
  EXPECT_THAT(decode("P2\n2 1\n10\n5 11\n"), HasSubstr("pixel 1 is 11, above maxval 10"));
  EXPECT_THAT(decode("P5\n0 3\n255\n"), HasSubstr("has no pixels"));
  EXPECT_THAT(decode("P5\nx 3\n255\n"), HasSubstr("expected the width as a decimal number, got 'x'"));
  // Refused from the header alone: no 400 MB raster is read or allocated.
  EXPECT_THAT(decode("P5\n20000 20000\n255\n"), HasSubstr("20000 x 20000 pixels exceed the limit of 40000000 cells"));
  const std::string png_bytes = encode_png(4, 4, PngFormat::kGray8, std::vector<std::uint8_t>(16, 0).data());
  EXPECT_THAT(decode(png_bytes.substr(0, png_bytes.size() - 20)), HasSubstr("corrupt PNG"));
  EXPECT_THAT(stvl::test::invalid_argument_of([&] { decode_map_image(png_bytes, "big.png", 15); }),
              HasSubstr("4 x 4 pixels exceed the limit of 15"));
}

TEST(Nav2MapErrors, LoadNamesTheMissingImageAndRefusesHugeOnesFromTheirHeader) {
  TempDir dir;
  const std::string yaml = dir.write("m.yaml", map_yaml("missing.pgm"));
  EXPECT_THAT(stvl::test::invalid_argument_of([&] { load_nav2_map(yaml); }),
              HasSubstr(yaml + ": image: cannot read '" + (dir.path() / "missing.pgm").string() + "'"));
  dir.write("huge.pgm", "P5\n# a comment\n20000 20000\n255\n");  // the raster left out: only the header is read
  const std::string huge = dir.write("huge.yaml", map_yaml("huge.pgm"));
  EXPECT_THAT(stvl::test::invalid_argument_of([&] { load_nav2_map(huge); }),
              HasSubstr("20000 x 20000 pixels exceed the limit"));
  EXPECT_THAT(stvl::test::invalid_argument_of([&] { load_nav2_map((dir.path() / "nope.yaml").string()); }),
              HasSubstr("cannot read the map's YAML file"));
}

}  // namespace
}  // namespace stvl::worldgen

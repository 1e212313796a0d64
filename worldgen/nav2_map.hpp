#pragma once
// nav2 / ROS map_server maps: the YAML (image, resolution, origin [x, y, yaw], negate, occupied_thresh,
// free_thresh, mode) and its image (PGM P5 / P2, 8- or 16-bit, comment lines; PNG of any colour type), turned
// into occupancy values exactly as nav2_map_server's map_io.cpp (loadMapFromFile) does:
//   shade = mean of the pixel's R, G, B (grey: the grey value) / maxval; in trinary mode an image with an alpha
//           channel averages the alpha (opacity, maxval = opaque) in as a fourth channel;
//   occ   = negate ? shade : 1 - shade;
//   trinary: 100 when occupied_thresh < occ, 0 when occ < free_thresh, -1 otherwise;
//   scale:   -1 when the pixel is not opaque; 100 / 0 as trinary; else rint((occ - free) / (occ_th - free) * 100);
//   raw:     round(shade * 255) when it lies in 0..100, -1 otherwise (negate and the thresholds unused).
// The image's top row is the map's last row (the map's row 0 lies at origin y).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace stvl::worldgen {

// No map bigger than this many cells is read (checked from the image header, before any pixel is allocated):
// 4e7 cells is a 316 m square at 0.05 m, far more than a building a camera run drives through.
inline constexpr std::size_t kMaxMapCells = 40'000'000;

enum class MapMode { kTrinary, kScale, kRaw };

// The map's YAML as map_server reads it. Every key but `mode` is required, as map_server requires them.
struct MapMetadata {
  std::string image;  // as written; image_path is it resolved against the YAML's folder
  std::string image_path;
  double resolution_m = 0;                                    // cell edge (m), finite and > 0
  double origin_x_m = 0, origin_y_m = 0, origin_yaw_rad = 0;  // the pose of cell (0, 0)'s outer corner
  bool negate = false;
  double occupied_thresh = 0.65, free_thresh = 0.25;  // 0 <= free < occupied <= 1
  MapMode mode = MapMode::kTrinary;
};

// An image's samples as decoded, before map_server's formula.
struct MapImage {
  int width = 0, height = 0;
  int channels = 1;                    // 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA
  int maxval = 255;                    // full scale of a sample (PGM's maxval, 255 or 65535 for PNG)
  std::vector<std::uint16_t> samples;  // top row first, `channels` per pixel
};

// A loaded map: map_server's OccupancyGrid values (-1 unknown, 0 free .. 100 occupied), row 0 at origin y.
struct Nav2Map {
  MapMetadata meta;
  int width = 0, height = 0;
  std::vector<std::int8_t> data;  // data[row * width + col]
  std::int8_t at(int col, int row) const { return data[static_cast<std::size_t>(row) * width + col]; }
};

// Reads the YAML text (`file_name` names it in errors, `yaml_dir` resolves a relative image path). Throws
// std::invalid_argument "FILE:LINE: KEY: what is wrong; the fix" for malformed YAML, a missing or unknown key
// (naming the nearest known one), a wrong type or a value out of range (resolution <= 0 or not finite, origin not
// three finite numbers, thresholds outside 0 <= free < occupied <= 1, an unknown mode).
MapMetadata parse_map_yaml(const std::string& text, const std::string& file_name, const std::string& yaml_dir);

// Decodes PGM (P5 binary or P2 plain, maxval 1..65535, '#' comments in the header) or PNG bytes, chosen by their
// magic. Throws std::invalid_argument naming `name` for any other magic, a malformed or truncated file, a sample
// above maxval, or more than max_cells pixels.
MapImage decode_map_image(const std::string& bytes, const std::string& name, std::size_t max_cells = kMaxMapCells);

// map_server's occupancy values of every pixel (see the top of this file).
Nav2Map to_occupancy(const MapImage& image, const MapMetadata& meta);

// parse_map_yaml, then the image file, then to_occupancy. Throws std::invalid_argument naming the YAML or the
// image file and the fix (a missing image names the path it looked for).
Nav2Map load_nav2_map(const std::string& yaml_path, std::size_t max_cells = kMaxMapCells);

const char* to_string(MapMode mode);

}  // namespace stvl::worldgen

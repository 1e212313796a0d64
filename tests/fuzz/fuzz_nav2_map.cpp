// nav2 map reader (worldgen/nav2_map.hpp): any bytes, read as an image (PGM or PNG) and as the map's YAML, either
// decode or throw std::invalid_argument naming the input (what `stvl-bench world from-map` turns into exit 2). A
// decoded image gives one occupancy value in -1..100 per pixel in every mode, and its walls merge into rectangles
// that cover exactly the occupied cells. Any other exception, crash or sanitizer report is a finding.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "worldgen/nav2_map.hpp"
#include "worldgen/occupancy.hpp"

namespace {

constexpr std::size_t kMaxCells = 1 << 20;  // what a fuzz input may allocate

void require(bool ok, const char* what) {
  if (ok) return;
  std::fprintf(stderr, "violated: %s\n", what);
  std::abort();
}

void names_input(const std::invalid_argument& e, const char* name) {
  if (std::string(e.what()).find(name) != std::string::npos) return;
  std::fprintf(stderr, "error message does not name %s: %s\n", name, e.what());
  std::abort();
}

void check_image(const stvl::worldgen::MapImage& image) {
  using namespace stvl::worldgen;
  const std::size_t cells = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
  require(image.width > 0 && image.height > 0 && cells <= kMaxCells, "image size within the cap");
  require(image.channels >= 1 && image.channels <= 4 && image.samples.size() == cells * image.channels, "sample count");
  for (std::uint16_t v : image.samples) require(v <= image.maxval, "samples within maxval");
  for (MapMode mode : {MapMode::kTrinary, MapMode::kScale, MapMode::kRaw})
    for (bool negate : {false, true}) {
      MapMetadata meta;
      meta.resolution_m = 0.05;
      meta.mode = mode;
      meta.negate = negate;
      const Nav2Map map = to_occupancy(image, meta);
      require(map.data.size() == cells, "one value per pixel");
      for (std::int8_t v : map.data) require(v >= -1 && v <= 100, "values in -1..100");
      if (mode != MapMode::kTrinary || negate || cells > 4096) continue;
      const OccupancyGrid grid = occupancy_from_nav2(map);
      std::vector<int> covered(cells, 0);
      for (const CellRect& r : merge_occupied(grid))
        for (int y = r.row; y < r.row + r.rows; ++y)
          for (int x = r.col; x < r.col + r.cols; ++x) ++covered[grid.frame.index({x, y})];
      for (std::size_t i = 0; i < cells; ++i)
        require(covered[i] == (grid.cells[i] == Cell::kOccupied ? 1 : 0), "merge covers the walls");
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    check_image(stvl::worldgen::decode_map_image(bytes, "fuzz.pgm", kMaxCells));
  } catch (const std::invalid_argument& e) {
    names_input(e, "fuzz.pgm");
  }
  try {
    const stvl::worldgen::MapMetadata m = stvl::worldgen::parse_map_yaml(bytes, "fuzz.yaml", "/maps");
    require(std::isfinite(m.resolution_m) && m.resolution_m > 0, "a finite resolution > 0");
    require(std::isfinite(m.origin_x_m + m.origin_y_m + m.origin_yaw_rad), "a finite origin");
    require(m.free_thresh >= 0 && m.free_thresh < m.occupied_thresh && m.occupied_thresh <= 1, "ordered thresholds");
    require(!m.image_path.empty(), "an image path");
  } catch (const std::invalid_argument& e) {
    names_input(e, "fuzz.yaml");
  }
  return 0;
}

#pragma once
// Shared by the tests of worldgen/: temporary folders, tiny maps written in the test, and a brute-force
// distance to a grid's occupied squares.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "worldgen/occupancy.hpp"

namespace stvl::worldgen::test {

namespace fs = std::filesystem;

// A fresh folder removed with the object.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    path_ =
        fs::temp_directory_path() / ("stvl_worldgen_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }
  std::string write(const std::string& name, const std::string& bytes) const {
    std::ofstream(path_ / name, std::ios::binary) << bytes;
    return (path_ / name).string();
  }

 private:
  fs::path path_;
};

// A binary PGM (P5) of 8-bit pixels, top row first, with a map_saver-like comment line.
inline std::string pgm_p5(int width, int height, const std::vector<int>& pixels, int maxval = 255) {
  std::string out = "P5\n# CREATOR: a test\n" + std::to_string(width) + " " + std::to_string(height) + "\n" +
                    std::to_string(maxval) + "\n";
  for (int v : pixels) {
    if (maxval > 255) out += static_cast<char>(v >> 8);
    out += static_cast<char>(v & 0xff);
  }
  return out;
}

// The YAML of a map with the given image and keys (mode empty: left out).
inline std::string map_yaml(const std::string& image, double resolution = 0.1,
                            const std::string& origin = "[0.0, 0.0, 0.0]", int negate = 0, double occupied = 0.65,
                            double free = 0.196, const std::string& mode = "trinary") {
  std::string yaml = "image: " + image + "\nresolution: " + std::to_string(resolution) + "\norigin: " + origin +
                     "\nnegate: " + std::to_string(negate) + "\noccupied_thresh: " + std::to_string(occupied) +
                     "\nfree_thresh: " + std::to_string(free) + "\n";
  if (!mode.empty()) yaml += "mode: " + mode + "\n";
  return yaml;
}

// An occupancy grid from rows written top row first ('#' occupied, '?' unknown, anything else free).
inline OccupancyGrid grid_from_rows(const std::vector<std::string>& rows, double resolution_m = 0.1) {
  OccupancyGrid g;
  g.frame.width = static_cast<int>(rows.front().size());
  g.frame.height = static_cast<int>(rows.size());
  g.frame.resolution_m = resolution_m;
  g.cells.resize(static_cast<std::size_t>(g.frame.width) * g.frame.height, Cell::kFree);
  for (int r = 0; r < g.frame.height; ++r)
    for (int c = 0; c < g.frame.width; ++c) {
      const char ch = rows[g.frame.height - 1 - r][c];
      g.cells[g.frame.index({c, r})] = ch == '#' ? Cell::kOccupied : ch == '?' ? Cell::kUnknown : Cell::kFree;
    }
  return g;
}

// Exact distance (m) from p_W to the nearest occupied cell's square; infinity without one.
inline double distance_to_occupied(const OccupancyGrid& g, const Eigen::Vector2d& p_W) {
  const Eigen::Vector2d p = g.frame.to_grid(p_W);
  double best = std::numeric_limits<double>::infinity();
  const double res = g.frame.resolution_m;
  for (int r = 0; r < g.frame.height; ++r)
    for (int c = 0; c < g.frame.width; ++c) {
      if (g.cells[g.frame.index({c, r})] != Cell::kOccupied) continue;
      const double dx = std::max({c * res - p.x(), 0.0, p.x() - (c + 1) * res});
      const double dy = std::max({r * res - p.y(), 0.0, p.y() - (r + 1) * res});
      best = std::min(best, std::hypot(dx, dy));
    }
  return best;
}

}  // namespace stvl::worldgen::test

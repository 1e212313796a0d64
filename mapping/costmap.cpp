#include "mapping/costmap.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "common/atomic_file.hpp"

namespace stvl::mapping {

std::optional<std::uint8_t> Costmap2D::at_world(double x_m, double y_m) const {
  const double ix = std::floor((x_m - origin_m.x()) / resolution_m);
  const double iy = std::floor((y_m - origin_m.y()) / resolution_m);
  if (!(ix >= 0 && iy >= 0 && ix < width && iy < height)) return std::nullopt;
  return at(static_cast<int>(ix), static_cast<int>(iy));
}

void write_costmap(const Costmap2D& costmap, const std::string& base_path) {
  if (costmap.width <= 0 || costmap.height <= 0 ||
      costmap.cells.size() != static_cast<std::size_t>(costmap.width) * costmap.height)
    throw std::invalid_argument("costmap is empty or its cells do not match " + std::to_string(costmap.width) + "x" +
                                std::to_string(costmap.height));
  std::string pgm = "P5\n" + std::to_string(costmap.width) + " " + std::to_string(costmap.height) + "\n255\n";
  const std::size_t header = pgm.size();
  pgm.resize(header + costmap.cells.size());
  for (int row = 0; row < costmap.height; ++row) {
    const int iy = costmap.height - 1 - row;
    for (int ix = 0; ix < costmap.width; ++ix) {
      const std::uint8_t cost = costmap.at(ix, iy);
      const char pixel = static_cast<char>(cost == kCostLethal ? 0 : cost == kCostFree ? 254 : 205);
      pgm[header + static_cast<std::size_t>(row) * costmap.width + ix] = pixel;
    }
  }
  const std::string pgm_path = base_path + ".pgm";
  std::string image_name = pgm_path;
  if (const auto slash = image_name.find_last_of('/'); slash != std::string::npos) image_name.erase(0, slash + 1);
  std::ostringstream yaml;
  yaml.precision(17);
  yaml << "image: " << image_name << "\n"
       << "mode: trinary\n"
       << "resolution: " << costmap.resolution_m << "\n"
       << "origin: [" << costmap.origin_m.x() << ", " << costmap.origin_m.y() << ", 0.0]\n"
       << "negate: 0\n"
       << "occupied_thresh: 0.65\n"
       << "free_thresh: 0.196\n";
  write_file_atomically(pgm_path, pgm);
  write_file_atomically(base_path + ".yaml", yaml.str());
}

}  // namespace stvl::mapping

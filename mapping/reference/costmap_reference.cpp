#include "mapping/reference/costmap_reference.hpp"

#include <cmath>

namespace stvl::mapping::reference {

std::vector<int> costmap_column_counts(const VoxelMap& map, const CostmapOptions& options, const Costmap2D& layout,
                                       std::size_t* outside) {
  std::vector<int> counts(static_cast<std::size_t>(layout.width) * static_cast<std::size_t>(layout.height), 0);
  std::size_t out = 0;
  map.for_each_key([&](const VoxelKey& k) {
    const Eigen::Vector3d c = map.center_of(k);
    if (c.z() < options.min_obstacle_height_m || c.z() > options.max_obstacle_height_m) return;
    const double ix = std::floor((c.x() - layout.origin_m.x()) / layout.resolution_m);
    const double iy = std::floor((c.y() - layout.origin_m.y()) / layout.resolution_m);
    if (!(ix >= 0 && iy >= 0 && ix < layout.width && iy < layout.height)) {
      ++out;
      return;
    }
    ++counts[static_cast<std::size_t>(iy) * layout.width + static_cast<std::size_t>(ix)];
  });
  if (outside) *outside = out;
  return counts;
}

}  // namespace stvl::mapping::reference

#include "filter/reference/voxel_grid.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>

namespace stvl::filter::reference {

Eigen::Matrix3Xf voxel_grid(const Eigen::Matrix3Xf& points, const VoxelGridConfig& config) {
  struct Sum {
    double x = 0, y = 0, z = 0;
    long count = 0;
  };
  // Keyed (z, y, x): the map's order is the documented output order, x fastest.
  std::map<std::array<std::int64_t, 3>, Sum> voxels;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const float x = points(0, i), y = points(1, i), z = points(2, i);
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) continue;
    auto index = [&](float v) { return static_cast<std::int64_t>(std::floor(double(v) / config.voxel_size_m)); };
    Sum& sum = voxels[{index(z), index(y), index(x)}];
    sum.x += x;
    sum.y += y;
    sum.z += z;
    ++sum.count;
  }
  const long min_points = std::max(config.min_points_per_voxel, 1);
  Eigen::Matrix3Xf out(3, static_cast<Eigen::Index>(voxels.size()));
  Eigen::Index kept = 0;
  for (const auto& [key, sum] : voxels) {
    if (sum.count < min_points) continue;
    const double c = double(sum.count);
    out.col(kept++) << static_cast<float>(sum.x / c), static_cast<float>(sum.y / c), static_cast<float>(sum.z / c);
  }
  out.conservativeResize(3, kept);
  return out;
}

}  // namespace stvl::filter::reference

// Written from the paper's description: X, Y, Z start as the voxel of the ray origin; stepX/Y/Z are the signs of
// the direction; tMaxX/Y/Z is the t at which the ray crosses the first voxel boundary on that axis and
// tDeltaX/Y/Z how far in t the ray moves to cross one voxel. Each iteration steps the axis whose tMax is the
// smallest and adds its tDelta. As the contract in mapping/ray_walk.hpp says, t is kept in fixed point (units of
// 2^-52), ties go to the lower axis (the paper's nested ifs send them to the higher one), and the walk stops
// before floor(e) or before a voxel entered at t >= 1.
#include "mapping/reference/ray_walk_reference.hpp"

#include <cmath>
#include <cstdint>
#include <limits>

namespace stvl::mapping::reference {

std::vector<VoxelKey> ray_voxels(const Eigen::Vector3d& s_vox, const Eigen::Vector3d& e_vox) {
  constexpr double kOne = 4503599627370496.0;      // 2^52: t = 1 in fixed point
  constexpr double kCap = 288230376151711744.0;    // 2^58
  constexpr double kMaxCoordinate = 1073741824.0;  // 2^30
  std::vector<VoxelKey> visited;
  for (const Eigen::Vector3d* p : {&s_vox, &e_vox})
    for (int a = 0; a < 3; ++a)
      if (!(std::abs((*p)[a]) < kMaxCoordinate)) return visited;  // also rejects NaN
  auto fixed = [&](double t) {
    return t * kOne < kCap ? static_cast<std::int64_t>(t * kOne + 0.5) : static_cast<std::int64_t>(kCap);
  };
  int voxel[3], last[3], step[3];
  std::int64_t t_max[3], t_delta[3];
  for (int a = 0; a < 3; ++a) {
    voxel[a] = static_cast<int>(std::floor(s_vox[a]));
    last[a] = static_cast<int>(std::floor(e_vox[a]));
    const double d = e_vox[a] - s_vox[a];
    step[a] = std::isfinite(1.0 / d) ? (d > 0.0 ? 1 : -1) : 0;  // d == 0 or subnormal: parallel to the axis
    const double boundary = step[a] > 0 ? voxel[a] + 1.0 : voxel[a];
    t_max[a] = step[a] != 0 ? fixed((boundary - s_vox[a]) * (1.0 / d)) : std::numeric_limits<std::int64_t>::max();
    t_delta[a] = step[a] != 0 ? fixed(std::abs(1.0 / d)) : 0;
  }
  while (voxel[0] != last[0] || voxel[1] != last[1] || voxel[2] != last[2]) {
    visited.push_back({voxel[0], voxel[1], voxel[2]});
    int a = 0;
    if (t_max[1] < t_max[a]) a = 1;
    if (t_max[2] < t_max[a]) a = 2;
    if (t_max[a] >= static_cast<std::int64_t>(kOne)) break;  // the next voxel starts beyond e
    voxel[a] += step[a];
    t_max[a] += t_delta[a];
  }
  return visited;
}

}  // namespace stvl::mapping::reference

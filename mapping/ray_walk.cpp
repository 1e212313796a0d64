#include "mapping/ray_walk.hpp"

#include <cmath>

namespace stvl::mapping {
namespace detail {
namespace {

// t (or t per voxel) as a double, to fixed point: round half up, capped at kTCap (beyond any t the walk uses).
std::int64_t to_fixed(double t) {
  const double scaled = t * static_cast<double>(kOne);
  return scaled < static_cast<double>(kTCap) ? static_cast<std::int64_t>(scaled + 0.5) : kTCap;
}

}  // namespace

bool setup_ray(const Eigen::Vector3d& s_vox, const Eigen::Vector3d& e_vox, RayAxes& ray) {
  constexpr double kMaxCoordinate = 1 << 30;  // keys and block origins (+ 8) stay far from int overflow
  if (!s_vox.allFinite() || !e_vox.allFinite()) return false;
  if (!(s_vox.cwiseAbs().maxCoeff() < kMaxCoordinate) || !(e_vox.cwiseAbs().maxCoeff() < kMaxCoordinate)) return false;
  for (int a = 0; a < 3; ++a) {
    const double d = e_vox[a] - s_vox[a];
    const double inv_d = 1.0 / d;  // +-inf where d is 0 or subnormal: never stepped
    ray.start[a] = static_cast<int>(std::floor(s_vox[a]));
    ray.end[a] = static_cast<int>(std::floor(e_vox[a]));
    ray.step[a] = !std::isfinite(inv_d) ? 0 : d > 0.0 ? 1 : -1;
    if (ray.step[a] == 0) {
      ray.t0[a] = kNever;
      ray.dt[a] = 0;
      continue;
    }
    const double exit_face = ray.start[a] + (ray.step[a] > 0 ? 1.0 : 0.0);
    ray.t0[a] = to_fixed((exit_face - s_vox[a]) * inv_d);
    ray.dt[a] = to_fixed(std::abs(inv_d));
  }
  return ray.start[0] != ray.end[0] || ray.start[1] != ray.end[1] || ray.start[2] != ray.end[2];
}

}  // namespace detail

std::vector<VoxelKey> ray_voxels(const Eigen::Vector3d& s_vox, const Eigen::Vector3d& e_vox) {
  std::vector<VoxelKey> keys;
  const int present = 1;
  walk_ray_blocks(
      s_vox, e_vox, [&](const VoxelKey&) { return &present; },
      [&](const int*, const VoxelKey& key) { keys.push_back(key); });
  return keys;
}

}  // namespace stvl::mapping

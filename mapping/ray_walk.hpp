#pragma once
// Voxel ray walk: the 3D DDA of Amanatides & Woo ("A Fast Voxel Traversal Algorithm for Ray Tracing", 1987) over
// 8^3-voxel blocks, jumping over blocks that hold nothing to visit. No OpenVDB: the caller says which blocks
// exist. Its plain voxel-by-voxel twin is mapping/reference/ray_walk_reference.hpp; tests/mapping compares them.
//
// Contract (ray-cast clearing relies on it; the reference implements the same):
// - The segment runs from s_vox to e_vox in voxel units: world point / voxel_size_m (divide rather than multiply
//   by the inverse, so that floor(e_vox) is exactly voxel_key(p_W, voxel_size_m)). Voxel k spans [k, k + 1).
// - Visited, in order: the start voxel floor(s_vox), then each voxel the walk enters, one face at a time
//   (6-connected), stopping before the first voxel that is the end voxel floor(e_vox) or that the walk enters at
//   t >= 1 (t: 0 at s_vox, 1 at e_vox). The end voxel is never visited; the start voxel is, unless it is the end
//   voxel, so a segment inside one voxel, or of zero length, visits nothing. The t >= 1 stop only matters where
//   rounding, or e_vox on a face, lets the path pass beside the end voxel.
// - Next face: the axis whose next face comes first in t. Ties (the ray through an edge or a corner) go to the
//   lower axis: x before y before z.
// - t in fixed point, units of 2^-52 (kOne = 1): on an axis with d = e - s != 0 the walk leaves the start voxel at
//   T0 = q((f - s) * (1 / d) * 2^52), f its exit face (floor(s) + 1 going up, floor(s) going down), and every
//   further voxel dT = q(|1 / d| * 2^52) later: the paper's tMax += tDelta, exact in integers, so a walk resumed
//   after a block jump agrees bit for bit. q(x) = floor(x + 0.5) computed as int64(x + 0.5), capped at 2^58
//   (beyond t = 64, never reached). An axis with d == 0, or whose 1 / d overflows, is never stepped.
// - Non-finite coordinates or |coordinate| >= 2^30 visit nothing.
#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "common/voxel_key.hpp"

namespace stvl::mapping {

// Every voxel of the walk (all blocks present), in order.
std::vector<VoxelKey> ray_voxels(const Eigen::Vector3d& s_vox, const Eigen::Vector3d& e_vox);

// The walk over blocks of 8^3 voxels (OpenVDB's leaf nodes; a block's origin is key & ~7 per axis).
// block_at(const VoxelKey& origin) returns a pointer or null; the walk crosses a null block without visiting its
// voxels, one step per block. visit(block, const VoxelKey& key) is called for each visited voxel of a non-null
// block. The visits are exactly ray_voxels(s_vox, e_vox) restricted to the non-null blocks, in the same order.
template <typename BlockAt, typename Visit>
void walk_ray_blocks(const Eigen::Vector3d& s_vox, const Eigen::Vector3d& e_vox, BlockAt&& block_at, Visit&& visit);

// ---- implementation ----------------------------------------------------------------------------------------

namespace detail {

constexpr std::int64_t kOne = std::int64_t{1} << 52;                       // t = 1
constexpr std::int64_t kTCap = std::int64_t{1} << 58;                      // q()'s cap
constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::max();  // an axis that is never stepped

struct RayAxes {
  std::int64_t t0[3];  // t at which the walk leaves the start voxel per axis (kNever: never)
  std::int64_t dt[3];  // t per voxel (0 where never stepped)
  int step[3];         // -1, 0 or +1
  int start[3], end[3];

  // t at which the walk leaves voxel k on axis a, k on the walk's side of the start (at most ~2^31 voxels on).
  std::int64_t exit_t(int a, int k) const {
    return step[a] == 0 ? kNever : t0[a] + static_cast<std::int64_t>((k - start[a]) * step[a]) * dt[a];
  }

  // The voxel index on stepped axis b just after the walk crossed, at t, a face normal to axis a: the crossings on
  // b made before it are those earlier than t, or at t when b < a (ties go to the lower axis).
  int entry_index(int b, int a, std::int64_t t) const {
    const std::int64_t limit = b < a ? t : t - 1;  // crossings at or before limit
    const std::int64_t crossings = t0[b] > limit ? 0 : (limit - t0[b]) / dt[b] + 1;
    return start[b] + step[b] * static_cast<int>(crossings);
  }
};

// floor() for |x| < 2^31, without a libm call (this runs once per ray and axis, twice).
inline int floor_to_int(double x) {
  const int i = static_cast<int>(x);
  return i > x ? i - 1 : i;
}

// t (or t per voxel) as a double, to fixed point: round half up, capped at kTCap (beyond any t the walk uses).
inline std::int64_t to_fixed(double t) {
  const double scaled = t * static_cast<double>(kOne);
  return scaled < static_cast<double>(kTCap) ? static_cast<std::int64_t>(scaled + 0.5) : kTCap;
}

// False when nothing is to be visited (bad input, or start voxel == end voxel). Inline: it costs as much as a
// short walk.
inline bool setup_ray(const Eigen::Vector3d& s_vox, const Eigen::Vector3d& e_vox, RayAxes& ray) {
  constexpr double kMaxCoordinate = 1 << 30;  // keys and block origins (+ 8) stay far from int overflow
  for (int a = 0; a < 3; ++a)
    if (!(std::abs(s_vox[a]) < kMaxCoordinate) || !(std::abs(e_vox[a]) < kMaxCoordinate)) return false;  // NaN too
  for (int a = 0; a < 3; ++a) {
    const double d = e_vox[a] - s_vox[a];
    const double inv_d = 1.0 / d;  // +-inf where d is 0 or subnormal: never stepped
    ray.start[a] = floor_to_int(s_vox[a]);
    ray.end[a] = floor_to_int(e_vox[a]);
    ray.step[a] = !(std::abs(inv_d) <= std::numeric_limits<double>::max()) ? 0 : d > 0.0 ? 1 : -1;
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

// Branch-free (cmov) on purpose: the axis a ray steps along is unpredictable. Ties go to the lower axis.
inline int argmin3(const std::int64_t t[3]) {
  const int a01 = static_cast<int>(t[1] < t[0]);
  const std::int64_t m01 = t[1] < t[0] ? t[1] : t[0];
  return t[2] < m01 ? 2 : a01;
}

// The voxels of one block, from cur, in scalars (indexing arrays by the stepped axis costs a store-to-load round
// trip per step). Returns false when the walk is over; true when it left the block (cur is then the next voxel).
template <bool kVisit, typename Block, typename Visit>
inline bool walk_block(const RayAxes& ray, int cur[3], const int block[3], Block* leaf, Visit& visit) {
  int cx = cur[0], cy = cur[1], cz = cur[2];
  std::int64_t tx = ray.exit_t(0, cx), ty = ray.exit_t(1, cy), tz = ray.exit_t(2, cz);
  const std::int64_t dx = ray.dt[0], dy = ray.dt[1], dz = ray.dt[2];
  const int sx = ray.step[0], sy = ray.step[1], sz = ray.step[2];
  for (;;) {
    if constexpr (kVisit) visit(leaf, VoxelKey{cx, cy, cz});
    const bool y_first = ty < tx;
    const std::int64_t t_xy = y_first ? ty : tx;
    const bool z_first = tz < t_xy;
    if ((z_first ? tz : t_xy) >= kOne) return false;  // the next voxel lies beyond e
    const bool x_step = !z_first && !y_first, y_step = !z_first && y_first;
    cx += x_step ? sx : 0;
    tx = x_step ? tx + dx : tx;
    cy += y_step ? sy : 0;
    ty = y_step ? ty + dy : ty;
    cz += z_first ? sz : 0;
    tz = z_first ? tz + dz : tz;
    if (((cx ^ block[0]) | (cy ^ block[1]) | (cz ^ block[2])) & ~7) break;  // next block: the caller's loop
    if (cx == ray.end[0] && cy == ray.end[1] && cz == ray.end[2]) return false;
  }
  cur[0] = cx;
  cur[1] = cy;
  cur[2] = cz;
  return true;
}

}  // namespace detail

template <typename BlockAt, typename Visit>
void walk_ray_blocks(const Eigen::Vector3d& s_vox, const Eigen::Vector3d& e_vox, BlockAt&& block_at, Visit&& visit) {
  detail::RayAxes ray;
  if (!detail::setup_ray(s_vox, e_vox, ray)) return;
  const int end_block[3] = {ray.end[0] & ~7, ray.end[1] & ~7, ray.end[2] & ~7};
  auto is_end_block = [&](const int b[3]) {
    return b[0] == end_block[0] && b[1] == end_block[1] && b[2] == end_block[2];
  };
  int cur[3] = {ray.start[0], ray.start[1], ray.start[2]};
  while (cur[0] != ray.end[0] || cur[1] != ray.end[1] || cur[2] != ray.end[2]) {
    int block[3] = {cur[0] & ~7, cur[1] & ~7, cur[2] & ~7};
    auto* leaf = block_at(VoxelKey{block[0], block[1], block[2]});
    if (leaf == nullptr && !is_end_block(block)) {
      // Block-level DDA to the next block with a leaf, or to the end's block (where the voxel walk finds whether
      // the path meets the end voxel); then the voxel walk resumes where the ray enters that block.
      std::int64_t tb[3];
      for (int a = 0; a < 3; ++a) tb[a] = ray.exit_t(a, ray.step[a] > 0 ? block[a] + 7 : block[a]);
      int a = 0;
      std::int64_t t = 0;
      for (;;) {
        a = detail::argmin3(tb);
        t = tb[a];
        if (t >= detail::kOne) return;  // the ray ends inside an empty block
        block[a] += 8 * ray.step[a];
        tb[a] += 8 * ray.dt[a];
        leaf = block_at(VoxelKey{block[0], block[1], block[2]});
        if (leaf != nullptr || is_end_block(block)) break;
      }
      cur[a] = ray.step[a] > 0 ? block[a] : block[a] + 7;
      for (int b = 0; b < 3; ++b)
        if (b != a && ray.step[b] != 0) cur[b] = ray.entry_index(b, a, t);
      if (cur[0] == ray.end[0] && cur[1] == ray.end[1] && cur[2] == ray.end[2]) return;
    }
    const bool more = leaf != nullptr ? detail::walk_block<true>(ray, cur, block, leaf, visit)
                                      : detail::walk_block<false>(ray, cur, block, leaf, visit);
    if (!more) return;
  }
}

}  // namespace stvl::mapping

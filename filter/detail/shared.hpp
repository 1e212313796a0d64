#pragma once
// Arithmetic shared by the CPU and CUDA code paths: every operation here must round identically on both,
// so device code uses the _rn intrinsics (no FMA contraction) and host code plain IEEE operations.
#include <cmath>
#include <cstdint>

#ifdef __CUDACC__
#define STVL_HD __host__ __device__ __forceinline__
#else
#define STVL_HD inline
#endif

namespace stvl::filter::detail {

STVL_HD std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// Counter-based: the same (seed, a, b) gives the same value anywhere.
STVL_HD std::uint64_t hash3(std::uint64_t seed, std::uint64_t a, std::uint64_t b) {
  return splitmix64(splitmix64(splitmix64(seed) ^ a) ^ b);
}

STVL_HD bool finite3(float x, float y, float z) { return std::isfinite(x) && std::isfinite(y) && std::isfinite(z); }

STVL_HD float sq_dist(float ax, float ay, float az, float bx, float by, float bz) {
#ifdef __CUDA_ARCH__
  const float dx = __fsub_rn(ax, bx), dy = __fsub_rn(ay, by), dz = __fsub_rn(az, bz);
  return __fadd_rn(__fadd_rn(__fmul_rn(dx, dx), __fmul_rn(dy, dy)), __fmul_rn(dz, dz));
#else
  const float dx = ax - bx, dy = ay - by, dz = az - bz;
  return (dx * dx + dy * dy) + dz * dz;
#endif
}

STVL_HD double sq_dist_d(double ax, double ay, double az, double bx, double by, double bz) {
#ifdef __CUDA_ARCH__
  const double dx = __dsub_rn(ax, bx), dy = __dsub_rn(ay, by), dz = __dsub_rn(az, bz);
  return __dadd_rn(__dadd_rn(__dmul_rn(dx, dx), __dmul_rn(dy, dy)), __dmul_rn(dz, dz));
#else
  const double dx = ax - bx, dy = ay - by, dz = az - bz;
  return (dx * dx + dy * dy) + dz * dz;
#endif
}

// floor(a / b) as an integer, exact for |a / b| < 2^62 (checked by make_voxel_layout); no libm call.
STVL_HD std::int64_t floor_div(double a, double b) {
  const double q = a / b;
  const std::int64_t t = static_cast<std::int64_t>(q);
  return t - (static_cast<double>(t) > q);
}

// Voxel grid: 64-bit mixed-radix key over the bounding box, x fastest.
struct VoxelLayout {
  double voxel_size_m = 1.0;
  std::int64_t base[3] = {0, 0, 0};   // floor(min / voxel) per axis
  std::uint64_t dims[3] = {1, 1, 1};  // voxels per axis
  int key_bits = 0;                   // bits of the largest key
  int index_bits = 0;                 // bits of the largest point index
  bool packed = true;                 // key_bits + index_bits <= 64: sort (key << index_bits | index)
};

STVL_HD std::uint64_t voxel_key(const VoxelLayout& l, float x, float y, float z) {
  const std::uint64_t ix = static_cast<std::uint64_t>(floor_div(double(x), l.voxel_size_m) - l.base[0]);
  const std::uint64_t iy = static_cast<std::uint64_t>(floor_div(double(y), l.voxel_size_m) - l.base[1]);
  const std::uint64_t iz = static_cast<std::uint64_t>(floor_div(double(z), l.voxel_size_m) - l.base[2]);
  return ix + l.dims[0] * (iy + l.dims[1] * iz);
}

// CSNB: 2^n cubes per axis of edge cube_edge_m from min_m; neighbours searched within `reach` cubes.
struct CsnbLayout {
  double min_m[3] = {0, 0, 0};
  double cube_edge_m = 1.0;
  int grid_exponent = 4;
  int reach = 1;
  float radius_sq = 0.f;  // (float)(voxel_size_m^2): neighbour when sq_dist < radius_sq
};

STVL_HD std::uint32_t cube_axis(const CsnbLayout& l, float v, int axis) {
  // floor_div: the same value as std::floor (the quotient is finite and small), without a libm call on the host.
  const double c = double(floor_div(double(v) - l.min_m[axis], l.cube_edge_m));
  const double top = double((1u << l.grid_exponent) - 1u);
  return static_cast<std::uint32_t>(c < 0.0 ? 0.0 : (c > top ? top : c));
}

STVL_HD std::uint32_t cube_key(const CsnbLayout& l, float x, float y, float z) {
  const int n = l.grid_exponent;
  return cube_axis(l, x, 0) | (cube_axis(l, y, 1) << n) | (cube_axis(l, z, 2) << (2 * n));
}

// Squared distance of a point to the centre of cube `key` (anchor choice), in double.
STVL_HD double centre_sq_dist(const CsnbLayout& l, std::uint32_t key, float x, float y, float z) {
  const int n = l.grid_exponent;
  const std::uint32_t mask = (1u << n) - 1u;
  const double e = l.cube_edge_m;
#ifdef __CUDA_ARCH__
  const double cx = __dadd_rn(l.min_m[0], __dmul_rn(double(key & mask) + 0.5, e));
  const double cy = __dadd_rn(l.min_m[1], __dmul_rn(double((key >> n) & mask) + 0.5, e));
  const double cz = __dadd_rn(l.min_m[2], __dmul_rn(double((key >> (2 * n)) & mask) + 0.5, e));
#else
  const double cx = l.min_m[0] + (double(key & mask) + 0.5) * e;
  const double cy = l.min_m[1] + (double((key >> n) & mask) + 0.5) * e;
  const double cz = l.min_m[2] + (double((key >> (2 * n)) & mask) + 0.5) * e;
#endif
  return sq_dist_d(double(x), double(y), double(z), cx, cy, cz);
}

// Random priority of a non-anchor point (input column `point_index`) for the batches, in the high 32 bits;
// the low 32 bits hold its sorted position, which breaks ties.
STVL_HD std::uint64_t csnb_priority(std::uint64_t seed, std::uint32_t point_index, std::uint32_t sorted_position) {
  return (hash3(seed, 0x43534E42ull, point_index) & 0xFFFFFFFF00000000ull) | sorted_position;
}

// The cubes within `reach` of cube `key` form (2 reach + 1)^2 rows of consecutive keys (x fastest):
// row r covers keys [lo, hi]; returns false when the row lies outside the grid.
STVL_HD bool csnb_row(const CsnbLayout& l, std::uint32_t key, int row, std::uint32_t* lo, std::uint32_t* hi) {
  const int n = l.grid_exponent;
  const int side = 2 * l.reach + 1;
  const int top = (1 << n) - 1;
  const int mask = top;
  const int cx = int(key) & mask, cy = (int(key) >> n) & mask, cz = (int(key) >> (2 * n)) & mask;
  const int y = cy + row % side - l.reach, z = cz + row / side - l.reach;
  if (y < 0 || y > top || z < 0 || z > top) return false;
  const int x0 = cx - l.reach < 0 ? 0 : cx - l.reach, x1 = cx + l.reach > top ? top : cx + l.reach;
  const std::uint32_t base = std::uint32_t(y << n) | std::uint32_t(z << (2 * n));
  *lo = base | std::uint32_t(x0);
  *hi = base | std::uint32_t(x1);
  return true;
}

STVL_HD int csnb_rows(const CsnbLayout& l) { return (2 * l.reach + 1) * (2 * l.reach + 1); }

// First index in sorted keys[0, count) with keys[i] >= value (or > value when `upper`).
STVL_HD std::uint32_t search_keys(const std::uint32_t* keys, std::uint32_t count, std::uint32_t value, bool upper) {
  std::uint32_t lo = 0, hi = count;
  while (lo < hi) {
    const std::uint32_t mid = lo + (hi - lo) / 2;
    if (upper ? keys[mid] <= value : keys[mid] < value) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

}  // namespace stvl::filter::detail

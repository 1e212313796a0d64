#include "evaluation/observe_keys.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace stvl::evaluation {
namespace {

// What every row of one frame shares.
struct Frame {
  const sensors::DepthImage* depth;
  std::vector<float> ray_x;  // per strided column, as pixel_ray_C() rounds it
  Eigen::Matrix3f R;         // T_world_camera in float, as the reference's cast gives it
  Eigen::Vector3f t;
  double range_m, min_z_m, max_z_m, voxel_m;
  double cy, fy;
};

// One strided row's keys and whether each pixel counts, without a branch (a loop the compiler vectorizes): the
// reference's Eigen expressions written out in Eigen's own order (p_C.norm() is sqrt(x^2 + (y^2 + z^2)), T * p is
// ((r0 x + r1 y) + r2 z) + t per row, no fused multiply-add), a pixel that does not count computed on zeros and
// dropped.
struct Row {
  std::vector<float> z;
  std::vector<std::int32_t> x_key, y_key, z_key;
  std::vector<std::int32_t> counts;  // 0 or 1, as wide as the keys: one vector length for the whole loop
};

[[gnu::always_inline]] inline void row_keys_body(const Frame& f, float ray_y, Row& r) {
  const Eigen::Matrix3f& R = f.R;
  const Eigen::Vector3f& t = f.t;
  const int n = static_cast<int>(r.z.size());
  for (int j = 0; j < n; ++j) {
    const float depth = r.z[j];
    const bool has_return = depth > 0.0f;
    const float z = has_return ? depth : 0.0f;
    const float px = z * f.ray_x[j], py = z * ray_y, pz = z * 1.0f;
    const float norm = std::sqrt(px * px + (py * py + pz * pz));
    const bool in_range = !(norm > f.range_m);
    const double wx = ((R(0, 0) * px + R(0, 1) * py) + R(0, 2) * pz) + t(0);
    const double wy = ((R(1, 0) * px + R(1, 1) * py) + R(1, 2) * pz) + t(1);
    const double wz = ((R(2, 0) * px + R(2, 1) * py) + R(2, 2) * pz) + t(2);
    const bool in_band = !(wz < f.min_z_m) & !(wz > f.max_z_m);
    const bool finite = (wx - wx == 0.0) & (wy - wy == 0.0) & (wz - wz == 0.0);
    const bool counts = has_return & in_range & in_band & finite;
    r.counts[j] = counts;
    r.x_key[j] = static_cast<std::int32_t>(std::floor((counts ? wx : 0.0) / f.voxel_m));
    r.y_key[j] = static_cast<std::int32_t>(std::floor((counts ? wy : 0.0) / f.voxel_m));
    r.z_key[j] = static_cast<std::int32_t>(std::floor((counts ? wz : 0.0) / f.voxel_m));
  }
}

void row_keys_plain(const Frame& f, float ray_y, Row& r) { row_keys_body(f, ray_y, r); }
#if defined(__x86_64__)
[[gnu::target("avx2")]] void row_keys_avx2(const Frame& f, float ray_y, Row& r) { row_keys_body(f, ray_y, r); }
bool have_avx2() { return __builtin_cpu_supports("avx2"); }
#else
void row_keys_avx2(const Frame& f, float ray_y, Row& r) { row_keys_body(f, ray_y, r); }
bool have_avx2() { return false; }
#endif

// Rows [row_begin, row_end) (in strided rows): their keys, sorted and unique. Neighbouring pixels mostly fall in
// one voxel: a key equal to its left or upper neighbour's (both already kept) is skipped before sorting.
void row_block_keys(const Frame& f, int row_begin, int row_end, std::vector<VoxelKey>& keys) {
  const sensors::DepthImage& depth = *f.depth;
  const std::size_t columns = f.ray_x.size();
  Row r;
  r.z.resize(columns), r.x_key.resize(columns), r.y_key.resize(columns), r.z_key.resize(columns);
  r.counts.resize(columns);
  const auto row_keys = have_avx2() ? &row_keys_avx2 : &row_keys_plain;
  bool have_last = false;
  VoxelKey last{};
  // The last key computed in each column (kept, or equal to a kept one); have_above: whether there is one.
  std::vector<VoxelKey> above(columns);
  std::vector<char> have_above(columns, 0);
  for (int row = row_begin; row < row_end; ++row) {
    const int v = row * kObserveStride;
    const float ray_y = static_cast<float>((v - f.cy) / f.fy);
    const float* pixels = depth.depth_m.data() + static_cast<std::size_t>(v) * depth.width;
    for (std::size_t j = 0; j < columns; ++j) r.z[j] = pixels[j * kObserveStride];
    row_keys(f, ray_y, r);
    for (std::size_t j = 0; j < columns; ++j) {
      if (!r.counts[j]) continue;
      const VoxelKey key{r.x_key[j], r.y_key[j], r.z_key[j]};
      const bool repeat = (have_last && key == last) || (have_above[j] && key == above[j]);
      have_last = true, last = key;
      have_above[j] = 1, above[j] = key;
      if (!repeat) keys.push_back(key);
    }
  }
  std::sort(keys.begin(), keys.end());  // each block sorted in parallel, then merged: the same sorted set
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
}

// Merges sorted `blocks` pairwise (log2(blocks) rounds) into blocks.front(); `scratch` is the merge buffer.
void merge_sorted_blocks(std::vector<std::vector<VoxelKey>>& blocks, std::vector<VoxelKey>& scratch) {
  for (std::size_t step = 1; step < blocks.size(); step *= 2)
    for (std::size_t b = 0; b + step < blocks.size(); b += 2 * step) {
      std::vector<VoxelKey>& a = blocks[b];
      std::vector<VoxelKey>& c = blocks[b + step];
      scratch.resize(a.size() + c.size());
      std::merge(a.begin(), a.end(), c.begin(), c.end(), scratch.begin());
      a.swap(scratch);
      std::vector<VoxelKey>().swap(c);
    }
}

}  // namespace

void observed_keys(const sensors::DepthImage& depth, const sensors::CameraIntrinsics& k,
                   const Eigen::Isometry3d& T_world_camera, double obstacle_range_m, const EvaluationConfig& config,
                   std::vector<VoxelKey>& keys) {
  const Eigen::Isometry3f T = T_world_camera.cast<float>();
  Frame f{&depth,
          {},
          T.linear(),
          T.translation(),
          obstacle_range_m,
          config.min_obstacle_height_m,
          config.max_obstacle_height_m,
          config.voxel_size_m,
          k.cy,
          k.fy};
  const int columns = (depth.width + kObserveStride - 1) / kObserveStride;
  f.ray_x.resize(static_cast<std::size_t>(columns));
  for (int j = 0; j < columns; ++j) f.ray_x[j] = static_cast<float>((j * kObserveStride - k.cx) / k.fx);
  // Rows in parallel, each block of rows keeping its own keys, then merged.
  const int rows = (depth.height + kObserveStride - 1) / kObserveStride;
  const int blocks = std::max(1, std::min(rows, 16));
  std::vector<std::vector<VoxelKey>> block_keys(static_cast<std::size_t>(blocks));
  tbb::parallel_for(0, blocks, [&](int b) {
    row_block_keys(f, b * rows / blocks, (b + 1) * rows / blocks, block_keys[static_cast<std::size_t>(b)]);
  });
  merge_sorted_blocks(block_keys, keys);
  keys.swap(block_keys.front());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
}

}  // namespace stvl::evaluation

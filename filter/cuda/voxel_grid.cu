// CUDA voxel grid. Same steps and arithmetic as voxel_grid.cpp (filter/detail/shared.hpp), so the output is
// bit-identical to the CPU's.
#include "filter/cuda/buffers.hpp"

namespace stvl::filter::cuda {

namespace {

__global__ void voxel_keys_packed(const float* p, std::size_t n, detail::VoxelLayout layout, std::uint64_t* items) {
  const std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  const float x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
  items[i] = detail::finite3(x, y, z) ? detail::voxel_key(layout, x, y, z) << layout.index_bits | i : ~0ull;
}

__global__ void voxel_keys_pairs(const float* p, std::size_t n, detail::VoxelLayout layout, std::uint64_t* keys,
                                 std::uint32_t* index) {
  const std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  const float x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
  keys[i] = detail::finite3(x, y, z) ? detail::voxel_key(layout, x, y, z) : ~0ull;
  index[i] = static_cast<std::uint32_t>(i);
}

__global__ void split_packed(const std::uint64_t* items, std::size_t m, int index_bits, std::uint64_t* keys,
                             std::uint32_t* index) {
  const std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (i >= m) return;
  keys[i] = items[i] >> index_bits;
  index[i] = static_cast<std::uint32_t>(items[i] & ((1ull << index_bits) - 1));
}

__global__ void centroids_kernel(const float* p, const std::uint32_t* index, const std::uint32_t* run_count,
                                 const std::uint32_t* run_begin, const int* runs, std::size_t m, int min_points,
                                 F3* centroid, std::uint8_t* keep) {
  const std::size_t r = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (r >= m) return;
  if (r >= std::size_t(*runs) || int(run_count[r]) < min_points) {
    keep[r] = 0;
    return;
  }
  double sx = 0, sy = 0, sz = 0;
  const std::uint32_t b = run_begin[r], e = b + run_count[r];
  for (std::uint32_t k = b; k < e; ++k) {
    const std::size_t q = index[k];
    sx += p[3 * q];
    sy += p[3 * q + 1];
    sz += p[3 * q + 2];
  }
  const double c = double(run_count[r]);
  centroid[r] = {static_cast<float>(sx / c), static_cast<float>(sy / c), static_cast<float>(sz / c)};
  keep[r] = 1;
}

}  // namespace

Eigen::Matrix3Xf Context::voxel_grid(const Eigen::Matrix3Xf& points, const VoxelGridConfig& config, MemoryMode mode) {
  detail::validate(config);
  detail::check_cloud_size(points.cols());
  Impl& d = *impl_;
  const std::size_t n = static_cast<std::size_t>(points.cols());
  if (n == 0) return Eigen::Matrix3Xf(3, 0);
  const float* p = d.upload(points, mode);
  const detail::Bounds bounds = d.compute_bounds(p, n);
  if (bounds.finite == 0) return Eigen::Matrix3Xf(3, 0);
  const detail::VoxelLayout layout = detail::make_voxel_layout(bounds, config.voxel_size_m, n);
  const std::size_t m = bounds.finite;
  d.keys.ensure(n);
  d.index.ensure(n);
  const std::uint64_t* sorted_keys;
  const std::uint32_t* sorted_index;
  if (layout.key_bits + layout.index_bits < 64) {  // one spare bit for the NaN sentinel
    d.items.ensure(n);
    d.items_alt.ensure(n);
    voxel_keys_packed<<<blocks(n), kBlock, 0, d.stream>>>(p, n, layout, d.items.ptr);
    const std::uint64_t* sorted =
        d.sort_keys(d.items, d.items_alt, n, layout.index_bits, layout.index_bits + layout.key_bits + 1);
    split_packed<<<blocks(m), kBlock, 0, d.stream>>>(sorted, m, layout.index_bits, d.keys.ptr, d.index.ptr);
    sorted_keys = d.keys.ptr;
    sorted_index = d.index.ptr;
  } else {
    d.items.ensure(n);
    d.index_alt.ensure(n);
    voxel_keys_pairs<<<blocks(n), kBlock, 0, d.stream>>>(p, n, layout, d.keys.ptr, d.index.ptr);
    cub::DoubleBuffer<std::uint64_t> k(d.keys.ptr, d.items.ptr);
    cub::DoubleBuffer<std::uint32_t> v(d.index.ptr, d.index_alt.ptr);
    d.cub_call([&](void* t, std::size_t& bytes) {
      return cub::DeviceRadixSort::SortPairs(t, bytes, k, v, static_cast<int>(n), 0, 64, d.stream);
    });
    sorted_keys = k.Current();
    sorted_index = v.Current();
  }
  d.unique_keys.ensure(m);
  d.run_count.ensure(m);
  d.run_begin.ensure(m);
  d.small.ensure(2);
  d.cub_call([&](void* t, std::size_t& bytes) {
    return cub::DeviceRunLengthEncode::Encode(t, bytes, sorted_keys, d.unique_keys.ptr, d.run_count.ptr, d.small.ptr,
                                              static_cast<int>(m), d.stream);
  });
  d.cub_call([&](void* t, std::size_t& bytes) {
    return cub::DeviceScan::ExclusiveSum(t, bytes, d.run_count.ptr, d.run_begin.ptr, static_cast<int>(m), d.stream);
  });
  d.centroids.ensure(m);
  d.keep.ensure(m);
  F3* target = d.output_target(m, mode);
  centroids_kernel<<<blocks(m), kBlock, 0, d.stream>>>(p, sorted_index, d.run_count.ptr, d.run_begin.ptr, d.small.ptr,
                                                       m, std::max(config.min_points_per_voxel, 1), d.centroids.ptr,
                                                       d.keep.ptr);
  d.cub_call([&](void* t, std::size_t& bytes) {
    return cub::DeviceSelect::Flagged(t, bytes, d.centroids.ptr, d.keep.ptr, target, d.small.ptr + 1,
                                      static_cast<int>(m), d.stream);
  });
  STVL_CUDA(cudaGetLastError());
  const int kept = d.read_int(d.small.ptr + 1);
  return d.download(target, static_cast<std::size_t>(kept), mode);
}

}  // namespace stvl::filter::cuda

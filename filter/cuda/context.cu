// CUDA voxel grid and CSNB. Same steps and arithmetic as voxel_grid.cpp / csnb.cpp (filter/detail/shared.hpp),
// so the outputs are bit-identical to the CPU's.
#include <cooperative_groups.h>
#include <cub/cub.cuh>

#include <cstring>
#include <stdexcept>
#include <string>

#include "filter/cuda/context.hpp"
#include "filter/detail/common.hpp"

namespace stvl::filter::cuda {

namespace {

void check(cudaError_t status, const char* what) {
  if (status != cudaSuccess) {
    throw std::runtime_error(std::string("cuda: ") + what + " failed: " + cudaGetErrorName(status) + " (" +
                             cudaGetErrorString(status) + ")");
  }
}
#define STVL_CUDA(call) check((call), #call)

constexpr int kBlock = 256;
inline unsigned blocks(std::size_t n) { return static_cast<unsigned>((n + kBlock - 1) / kBlock); }

template <class T>
struct DeviceBuffer {
  T* ptr = nullptr;
  std::size_t capacity = 0;
  void ensure(std::size_t n) {
    if (n <= capacity) return;
    if (ptr) cudaFree(ptr);
    ptr = nullptr;
    capacity = 0;
    STVL_CUDA(cudaMalloc(&ptr, std::max<std::size_t>(n, 1) * sizeof(T)));
    capacity = n;
  }
  ~DeviceBuffer() {
    if (ptr) cudaFree(ptr);
  }
};

// Host memory of one kind (pinned, mapped or managed), grown on demand.
struct HostBuffer {
  MemoryMode mode = MemoryMode::kPinned;
  float* ptr = nullptr;
  float* device_ptr = nullptr;
  std::size_t capacity = 0;
  void release() {
    if (!ptr) return;
    if (mode == MemoryMode::kManaged) cudaFree(ptr); else cudaFreeHost(ptr);
    ptr = device_ptr = nullptr;
    capacity = 0;
  }
  void ensure(std::size_t floats, MemoryMode wanted) {
    if (floats <= capacity && wanted == mode) return;
    release();
    mode = wanted;
    const std::size_t bytes = std::max<std::size_t>(floats, 1) * sizeof(float);
    if (mode == MemoryMode::kManaged) {
      std::size_t free_bytes = 0, total_bytes = 0;
      STVL_CUDA(cudaMemGetInfo(&free_bytes, &total_bytes));
      if (bytes > free_bytes) {
        throw std::runtime_error("cuda: managed buffer of " + std::to_string(bytes) + " bytes exceeds the " +
                                 std::to_string(free_bytes) + " bytes free on the GPU");
      }
      STVL_CUDA(cudaMallocManaged(&ptr, bytes));
      device_ptr = ptr;
    } else if (mode == MemoryMode::kMapped) {
      STVL_CUDA(cudaHostAlloc(&ptr, bytes, cudaHostAllocMapped));
      STVL_CUDA(cudaHostGetDevicePointer(&device_ptr, ptr, 0));
    } else {
      STVL_CUDA(cudaHostAlloc(&ptr, bytes, cudaHostAllocDefault));
      device_ptr = nullptr;
    }
    capacity = floats;
  }
  ~HostBuffer() { release(); }
};

struct F3 {
  float x, y, z;
};

struct DeviceBounds {
  int min[3];
  int max[3];
  unsigned long long finite;
};

__device__ __forceinline__ int float_order(float f) {
  const int i = __float_as_int(f);
  return i >= 0 ? i : i ^ 0x7FFFFFFF;
}
inline float order_float(int i) {
  const int bits = i >= 0 ? i : i ^ 0x7FFFFFFF;
  float f;
  std::memcpy(&f, &bits, sizeof(f));
  return f;
}

__global__ void bounds_kernel(const float* p, std::size_t n, DeviceBounds* out) {
  int lo[3] = {INT_MAX, INT_MAX, INT_MAX}, hi[3] = {INT_MIN, INT_MIN, INT_MIN};
  unsigned long long count = 0;
  for (std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x; i < n; i += std::size_t(gridDim.x) * blockDim.x) {
    const float v[3] = {p[3 * i], p[3 * i + 1], p[3 * i + 2]};
    if (!detail::finite3(v[0], v[1], v[2])) continue;
    ++count;
    for (int a = 0; a < 3; ++a) {
      lo[a] = min(lo[a], float_order(v[a]));
      hi[a] = max(hi[a], float_order(v[a]));
    }
  }
  for (int offset = 16; offset > 0; offset /= 2) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = min(lo[a], __shfl_down_sync(0xFFFFFFFFu, lo[a], offset));
      hi[a] = max(hi[a], __shfl_down_sync(0xFFFFFFFFu, hi[a], offset));
    }
    count += __shfl_down_sync(0xFFFFFFFFu, count, offset);
  }
  if (threadIdx.x % 32 == 0) {
    for (int a = 0; a < 3; ++a) {
      atomicMin(&out->min[a], lo[a]);
      atomicMax(&out->max[a], hi[a]);
    }
    if (count) atomicAdd(&out->finite, count);
  }
}

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

// ---- CSNB ----
__global__ void csnb_keys(const float* p, std::size_t n, detail::CsnbLayout layout, int index_bits, std::uint64_t* items) {
  const std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  const float x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
  items[i] = detail::finite3(x, y, z) ? std::uint64_t(detail::cube_key(layout, x, y, z)) << index_bits | i : ~0ull;
}

__global__ void csnb_gather(const float* p, const std::uint64_t* items, std::size_t m, int index_bits, F3* xyz,
                            std::uint32_t* column, std::uint32_t* key) {
  const std::size_t s = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (s >= m) return;
  const std::uint32_t i = static_cast<std::uint32_t>(items[s] & ((1ull << index_bits) - 1));
  xyz[s] = {p[3 * std::size_t(i)], p[3 * std::size_t(i) + 1], p[3 * std::size_t(i) + 2]};
  column[s] = i;
  key[s] = static_cast<std::uint32_t>(items[s] >> index_bits);
}

__global__ void csnb_cubes(detail::CsnbLayout layout, const std::uint32_t* cube_key, const std::uint32_t* cube_begin,
                           std::uint32_t cubes, const F3* xyz, std::uint32_t* spans, std::uint32_t* anchor,
                           std::uint32_t* cube_of, std::uint8_t* is_anchor) {
  const std::uint32_t c = blockIdx.x * blockDim.x + threadIdx.x;
  if (c >= cubes) return;
  const int rows = detail::csnb_rows(layout);
  for (int r = 0; r < rows; ++r) {
    std::uint32_t lo, hi, b = 0, e = 0;
    if (detail::csnb_row(layout, cube_key[c], r, &lo, &hi)) {
      b = cube_begin[detail::search_keys(cube_key, cubes, lo, false)];
      e = cube_begin[detail::search_keys(cube_key, cubes, hi, true)];
    }
    spans[(std::size_t(c) * rows + r) * 2] = b;
    spans[(std::size_t(c) * rows + r) * 2 + 1] = e;
  }
  std::uint32_t best = cube_begin[c];
  double best_d = detail::centre_sq_dist(layout, cube_key[c], xyz[best].x, xyz[best].y, xyz[best].z);
  for (std::uint32_t s = cube_begin[c]; s < cube_begin[c + 1]; ++s) {
    cube_of[s] = c;
    is_anchor[s] = 0;
    const double d = detail::centre_sq_dist(layout, cube_key[c], xyz[s].x, xyz[s].y, xyz[s].z);
    if (d < best_d) {
      best_d = d;
      best = s;
    }
  }
  anchor[c] = best;
}

__global__ void csnb_mark_anchors(const std::uint32_t* anchor, std::uint32_t cubes, std::uint8_t* is_anchor) {
  const std::uint32_t c = blockIdx.x * blockDim.x + threadIdx.x;
  if (c < cubes) is_anchor[anchor[c]] = 1;
}

__global__ void csnb_count(const F3* xyz, std::uint32_t m, const std::uint32_t* cube_of, const std::uint32_t* spans,
                           int rows, float r2, int* count, std::uint8_t* live) {
  const std::uint32_t s = blockIdx.x * blockDim.x + threadIdx.x;
  if (s >= m) return;
  const F3 p = xyz[s];
  const std::uint32_t* span = spans + std::size_t(cube_of[s]) * rows * 2;
  int k = 0;
  for (int r = 0; r < rows; ++r) {
    for (std::uint32_t j = span[2 * r]; j < span[2 * r + 1]; ++j) {
      const F3 q = xyz[j];
      k += (detail::sq_dist(p.x, p.y, p.z, q.x, q.y, q.z) < r2) & (j != s);
    }
  }
  count[s] = k;
  live[s] = 1;
}

__global__ void csnb_priorities(const std::uint32_t* column, const std::uint8_t* is_anchor, std::uint32_t m,
                                std::uint64_t seed, std::uint64_t* order, std::uint8_t* flag) {
  const std::uint32_t s = blockIdx.x * blockDim.x + threadIdx.x;
  if (s >= m) return;
  order[s] = detail::csnb_priority(seed, column[s], s);
  flag[s] = !is_anchor[s];
}

__global__ void csnb_flags(const std::uint64_t* order, std::size_t window, const std::uint8_t* live, const int* count,
                           int threshold, int* flag) {
  const std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (i >= window) return;
  const std::uint32_t s = static_cast<std::uint32_t>(order[i]);
  flag[i] = live[s] && count[s] > threshold;
}

// result[0]: marked in the window, result[1]: window position of the (K+1)-th marked point.
__global__ void csnb_pick(const std::uint64_t* order, std::size_t window, const int* flag, const int* pos, int batch,
                          std::uint32_t* picked, long long* result) {
  const std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (i >= window) return;
  if (flag[i] && pos[i] < batch) picked[pos[i]] = static_cast<std::uint32_t>(order[i]);
  if (flag[i] && pos[i] == batch) result[1] = static_cast<long long>(i);
  if (i == window - 1) result[0] = pos[i] + flag[i];
}

__global__ void csnb_kill(const std::uint32_t* picked, int count, std::uint8_t* live) {
  const int q = blockIdx.x * blockDim.x + threadIdx.x;
  if (q < count) live[picked[q]] = 0;
}

__global__ void csnb_decrement(const std::uint32_t* picked, int batch, const F3* xyz, const std::uint32_t* cube_of,
                               const std::uint32_t* spans, int rows, float r2, const std::uint8_t* live, int* count) {
  const int q = blockIdx.x * blockDim.x + threadIdx.x;
  if (q >= batch) return;
  const std::uint32_t s = picked[q];
  const F3 p = xyz[s];
  const std::uint32_t* span = spans + std::size_t(cube_of[s]) * rows * 2;
  for (int r = 0; r < rows; ++r) {
    for (std::uint32_t j = span[2 * r]; j < span[2 * r + 1]; ++j) {
      const F3 o = xyz[j];
      if (live[j] && detail::sq_dist(p.x, p.y, p.z, o.x, o.y, o.z) < r2) atomicSub(&count[j], 1);
    }
  }
}

// The whole batch loop in one cooperative kernel, one grid-wide barrier per phase and no host round trip.
// Phase A: every block walks the same window of the random order and finds the same batch (the first K
// marked points at or after the cursor, and the position of the (K+1)-th), reading counts and live flags
// that no one writes in this phase, so the choice depends on the data only, never on timing. Phase B: one
// warp per batch point kills it and decrements its neighbours (integer atomics: order-free). Decrementing
// points that are dead, the batch included, is harmless: a dead point's count is never read again.
constexpr int kLoopBlock = 512;

struct LoopParams {
  const std::uint64_t* order;
  unsigned long long candidates;
  const F3* xyz;
  const std::uint32_t* cube_of;
  const std::uint32_t* spans;
  int rows;
  float r2;
  std::uint8_t* live;
  int* count;
  int threshold;
  int batch;
  std::uint32_t* picked;
};

__global__ void __launch_bounds__(kLoopBlock) csnb_loop(LoopParams P) {
  namespace cg = cooperative_groups;
  cg::grid_group grid = cg::this_grid();
  using Scan = cub::BlockScan<int, kLoopBlock>;
  __shared__ typename Scan::TempStorage scan_storage;
  __shared__ long long s_next;
  constexpr int kWarps = kLoopBlock / 32;
  const int lane = threadIdx.x % 32;
  const int total_warps = gridDim.x * kWarps;
  const int global_warp = blockIdx.x * kWarps + threadIdx.x / 32;
  unsigned long long cursor = 0;
  while (cursor < P.candidates) {
    if (threadIdx.x == 0) s_next = -1;
    __syncthreads();
    int found = 0;
    for (unsigned long long base = cursor; base < P.candidates; base += kLoopBlock) {
      const unsigned long long i = base + threadIdx.x;
      int flag = 0;
      std::uint32_t s = 0;
      if (i < P.candidates) {
        s = static_cast<std::uint32_t>(P.order[i]);
        flag = __ldcg(P.live + s) && __ldcg(P.count + s) > P.threshold;
      }
      int pos, total;
      Scan(scan_storage).ExclusiveSum(flag, pos, total);
      if (flag) {
        const int q = found + pos;
        if (q < P.batch) {
          if (blockIdx.x == 0) P.picked[q] = s;
        } else if (q == P.batch) {
          s_next = static_cast<long long>(i);
        }
      }
      found += total;
      __syncthreads();
      if (found > P.batch) break;
    }
    const long long next = s_next;
    const int batch = min(found, P.batch);
    grid.sync();
    for (int q = global_warp; q < batch; q += total_warps) {
      const std::uint32_t s = __ldcg(P.picked + q);
      if (lane == 0) P.live[s] = 0;
      const F3 p = P.xyz[s];
      const std::uint32_t* span = P.spans + std::size_t(P.cube_of[s]) * P.rows * 2;
      for (int r = 0; r < P.rows; ++r) {
        const std::uint32_t e = span[2 * r + 1];
        for (std::uint32_t j = span[2 * r] + lane; j < e; j += 32) {
          const F3 o = P.xyz[j];
          if (detail::sq_dist(p.x, p.y, p.z, o.x, o.y, o.z) < P.r2) atomicSub(P.count + j, 1);
        }
      }
    }
    if (found <= P.batch) break;  // the same in every block
    cursor = static_cast<unsigned long long>(next);
    grid.sync();
  }
}

__global__ void csnb_claims(const std::uint32_t* anchor, std::uint32_t cubes, const F3* xyz, const std::uint32_t* spans,
                            int rows, float r2, const int* count, int threshold, const std::uint8_t* is_anchor,
                            std::uint8_t* live) {
  const std::uint32_t c = blockIdx.x * blockDim.x + threadIdx.x;
  if (c >= cubes) return;
  const std::uint32_t a = anchor[c];
  if (count[a] <= threshold) return;
  const F3 p = xyz[a];
  const std::uint32_t* span = spans + std::size_t(c) * rows * 2;
  for (int r = 0; r < rows; ++r) {
    for (std::uint32_t j = span[2 * r]; j < span[2 * r + 1]; ++j) {
      const F3 o = xyz[j];
      if (!is_anchor[j] && detail::sq_dist(p.x, p.y, p.z, o.x, o.y, o.z) < r2) live[j] = 0;
    }
  }
}

}  // namespace

bool device_available(std::string* reason) {
  int count = 0;
  const cudaError_t status = cudaGetDeviceCount(&count);
  if (status != cudaSuccess) {
    cudaGetLastError();
    if (reason) {
      *reason = std::string("cudaGetDeviceCount: ") + cudaGetErrorName(status) + " (error " +
                std::to_string(int(status)) + ")";
    }
    return false;
  }
  if (count == 0) {
    if (reason) *reason = "no CUDA device";
    return false;
  }
  if (reason) reason->clear();
  return true;
}

struct Context::Impl {
  cudaStream_t stream = nullptr;
  DeviceBuffer<float> input;
  DeviceBuffer<F3> output;
  HostBuffer host_in, host_out;
  DeviceBuffer<DeviceBounds> bounds;
  DeviceBuffer<std::uint64_t> items, items_alt, keys, unique_keys;
  DeviceBuffer<std::uint32_t> index, index_alt, run_count, run_begin;
  DeviceBuffer<int> small;
  DeviceBuffer<F3> centroids, xyz;
  DeviceBuffer<std::uint8_t> keep, live, is_anchor;
  DeviceBuffer<unsigned char> temp;
  DeviceBuffer<std::uint32_t> column, key32, cube_key, cube_count, cube_begin, cube_of, spans, anchor, picked;
  DeviceBuffer<int> count, flag, pos;
  DeviceBuffer<std::uint64_t> order, order_alt;
  DeviceBuffer<long long> result;
  int loop_grid = -1;  // blocks of the cooperative CSNB loop; 0: not supported, use the host loop

  // Makes `points` readable by kernels according to `mode`; returns the device-side pointer.
  const float* upload(const Eigen::Matrix3Xf& points, MemoryMode mode) {
    const std::size_t floats = static_cast<std::size_t>(points.size());
    if (mode == MemoryMode::kCopy) {
      input.ensure(floats);
      STVL_CUDA(cudaMemcpyAsync(input.ptr, points.data(), floats * sizeof(float), cudaMemcpyHostToDevice, stream));
      return input.ptr;
    }
    host_in.ensure(floats, mode);
    std::memcpy(host_in.ptr, points.data(), floats * sizeof(float));
    if (mode == MemoryMode::kPinned) {
      input.ensure(floats);
      STVL_CUDA(cudaMemcpyAsync(input.ptr, host_in.ptr, floats * sizeof(float), cudaMemcpyHostToDevice, stream));
      return input.ptr;
    }
    if (mode == MemoryMode::kManaged) prefetch(host_in.ptr, floats * sizeof(float), true);
    return host_in.device_ptr;  // mapped (zero-copy) or managed
  }

  // Managed memory: move the pages in one DMA instead of page faults (best effort: errors are ignored).
  void prefetch(const void* ptr, std::size_t bytes, bool to_device) {
    if (bytes == 0) return;
    int device = 0;
    if (cudaGetDevice(&device) != cudaSuccess) return;
    cudaMemLocation location{};
    location.type = to_device ? cudaMemLocationTypeDevice : cudaMemLocationTypeHost;
    location.id = to_device ? device : 0;
    if (cudaMemPrefetchAsync(ptr, bytes, location, 0, stream) != cudaSuccess) cudaGetLastError();
  }

  // Where the final kernel writes `capacity` points.
  F3* output_target(std::size_t capacity, MemoryMode mode) {
    if (mode == MemoryMode::kMapped || mode == MemoryMode::kManaged) {
      host_out.ensure(capacity * 3, mode);
      return reinterpret_cast<F3*>(host_out.device_ptr);
    }
    output.ensure(capacity);
    return output.ptr;
  }

  Eigen::Matrix3Xf download(const F3* target, std::size_t points, MemoryMode mode) {
    Eigen::Matrix3Xf out(3, static_cast<Eigen::Index>(points));
    const std::size_t bytes = points * sizeof(F3);
    if (mode == MemoryMode::kCopy) {
      STVL_CUDA(cudaMemcpyAsync(out.data(), target, bytes, cudaMemcpyDeviceToHost, stream));
      STVL_CUDA(cudaStreamSynchronize(stream));
    } else if (mode == MemoryMode::kPinned) {
      host_out.ensure(points * 3, MemoryMode::kPinned);
      STVL_CUDA(cudaMemcpyAsync(host_out.ptr, target, bytes, cudaMemcpyDeviceToHost, stream));
      STVL_CUDA(cudaStreamSynchronize(stream));
      std::memcpy(out.data(), host_out.ptr, bytes);
    } else {
      if (mode == MemoryMode::kManaged) prefetch(host_out.ptr, bytes, false);
      STVL_CUDA(cudaStreamSynchronize(stream));
      std::memcpy(out.data(), host_out.ptr, bytes);
    }
    return out;
  }

  detail::Bounds compute_bounds(const float* p, std::size_t n) {
    DeviceBounds init;
    for (int a = 0; a < 3; ++a) {
      init.min[a] = INT_MAX;
      init.max[a] = INT_MIN;
    }
    init.finite = 0;
    bounds.ensure(1);
    STVL_CUDA(cudaMemcpyAsync(bounds.ptr, &init, sizeof(init), cudaMemcpyHostToDevice, stream));
    const unsigned grid = std::min<unsigned>(blocks(n), 1024);
    bounds_kernel<<<grid, kBlock, 0, stream>>>(p, n, bounds.ptr);
    STVL_CUDA(cudaGetLastError());
    DeviceBounds result_host;
    STVL_CUDA(cudaMemcpyAsync(&result_host, bounds.ptr, sizeof(result_host), cudaMemcpyDeviceToHost, stream));
    STVL_CUDA(cudaStreamSynchronize(stream));
    detail::Bounds b;
    b.finite = result_host.finite;
    for (int a = 0; a < 3; ++a) {
      b.min[a] = order_float(result_host.min[a]);
      b.max[a] = order_float(result_host.max[a]);
    }
    return b;
  }

  template <class Fn>
  void cub_call(Fn&& fn) {
    std::size_t bytes = 0;
    STVL_CUDA(fn(nullptr, bytes));
    temp.ensure(bytes);
    STVL_CUDA(fn(temp.ptr, bytes));
  }

  // Sorts items[0, n) on bits [low, high); returns the buffer holding the result.
  std::uint64_t* sort_keys(DeviceBuffer<std::uint64_t>& a, DeviceBuffer<std::uint64_t>& b, std::size_t n, int low, int high) {
    cub::DoubleBuffer<std::uint64_t> db(a.ptr, b.ptr);
    cub_call([&](void* t, std::size_t& bytes) {
      return cub::DeviceRadixSort::SortKeys(t, bytes, db, static_cast<int>(n), low, high, stream);
    });
    return db.Current();
  }

  int read_int(const int* device) {
    int value = 0;
    STVL_CUDA(cudaMemcpyAsync(&value, device, sizeof(int), cudaMemcpyDeviceToHost, stream));
    STVL_CUDA(cudaStreamSynchronize(stream));
    return value;
  }
};

Context::Context() : impl_(std::make_unique<Impl>()) {
  std::string reason;
  if (!device_available(&reason)) throw std::runtime_error("filter: device 'cuda' unavailable: " + reason);
  STVL_CUDA(cudaStreamCreateWithFlags(&impl_->stream, cudaStreamNonBlocking));
}

Context::~Context() {
  if (impl_ && impl_->stream) cudaStreamDestroy(impl_->stream);
}

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
    const std::uint64_t* sorted = d.sort_keys(d.items, d.items_alt, n, layout.index_bits,
                                              layout.index_bits + layout.key_bits + 1);
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
  centroids_kernel<<<blocks(m), kBlock, 0, d.stream>>>(p, sorted_index, d.run_count.ptr, d.run_begin.ptr, d.small.ptr, m,
                                                        std::max(config.min_points_per_voxel, 1), d.centroids.ptr, d.keep.ptr);
  d.cub_call([&](void* t, std::size_t& bytes) {
    return cub::DeviceSelect::Flagged(t, bytes, d.centroids.ptr, d.keep.ptr, target, d.small.ptr + 1,
                                      static_cast<int>(m), d.stream);
  });
  STVL_CUDA(cudaGetLastError());
  const int kept = d.read_int(d.small.ptr + 1);
  return d.download(target, static_cast<std::size_t>(kept), mode);
}

Eigen::Matrix3Xf Context::csnb(const Eigen::Matrix3Xf& points, const CsnbConfig& config, MemoryMode mode) {
  detail::validate(config);
  detail::check_cloud_size(points.cols());
  Impl& d = *impl_;
  const std::size_t n = static_cast<std::size_t>(points.cols());
  if (n == 0) return Eigen::Matrix3Xf(3, 0);
  const float* p = d.upload(points, mode);
  const detail::Bounds bounds = d.compute_bounds(p, n);
  if (bounds.finite == 0) return Eigen::Matrix3Xf(3, 0);
  const detail::CsnbLayout layout = detail::make_csnb_layout(bounds, config);
  const std::uint32_t m = static_cast<std::uint32_t>(bounds.finite);
  const int index_bits = std::max(1, detail::bit_width(n - 1));
  const int key_bits = 3 * layout.grid_exponent;
  d.items.ensure(n);
  d.items_alt.ensure(n);
  csnb_keys<<<blocks(n), kBlock, 0, d.stream>>>(p, n, layout, index_bits, d.items.ptr);
  const std::uint64_t* sorted = d.sort_keys(d.items, d.items_alt, n, index_bits, std::min(64, index_bits + key_bits + 1));
  d.xyz.ensure(m);
  d.column.ensure(m);
  d.key32.ensure(m);
  csnb_gather<<<blocks(m), kBlock, 0, d.stream>>>(p, sorted, m, index_bits, d.xyz.ptr, d.column.ptr, d.key32.ptr);
  d.cube_key.ensure(m);
  d.cube_count.ensure(m);
  d.cube_begin.ensure(m + 1);
  d.small.ensure(2);
  d.cub_call([&](void* t, std::size_t& bytes) {
    return cub::DeviceRunLengthEncode::Encode(t, bytes, d.key32.ptr, d.cube_key.ptr, d.cube_count.ptr, d.small.ptr,
                                              static_cast<int>(m), d.stream);
  });
  const std::uint32_t cubes = static_cast<std::uint32_t>(d.read_int(d.small.ptr));
  d.cub_call([&](void* t, std::size_t& bytes) {
    return cub::DeviceScan::ExclusiveSum(t, bytes, d.cube_count.ptr, d.cube_begin.ptr, static_cast<int>(cubes), d.stream);
  });
  STVL_CUDA(cudaMemcpyAsync(d.cube_begin.ptr + cubes, &m, sizeof(m), cudaMemcpyHostToDevice, d.stream));
  const int rows = detail::csnb_rows(layout);
  d.spans.ensure(std::size_t(cubes) * rows * 2);
  d.anchor.ensure(cubes);
  d.cube_of.ensure(m);
  d.is_anchor.ensure(m);
  d.live.ensure(m);
  d.count.ensure(m);
  csnb_cubes<<<blocks(cubes), kBlock, 0, d.stream>>>(layout, d.cube_key.ptr, d.cube_begin.ptr, cubes, d.xyz.ptr,
                                                      d.spans.ptr, d.anchor.ptr, d.cube_of.ptr, d.is_anchor.ptr);
  csnb_mark_anchors<<<blocks(cubes), kBlock, 0, d.stream>>>(d.anchor.ptr, cubes, d.is_anchor.ptr);
  csnb_count<<<blocks(m), kBlock, 0, d.stream>>>(d.xyz.ptr, m, d.cube_of.ptr, d.spans.ptr, rows, layout.radius_sq,
                                                  d.count.ptr, d.live.ptr);
  // Random order of the non-anchor points (see csnb.cpp for why one order serves every batch).
  d.order.ensure(m);
  d.order_alt.ensure(m);
  d.keep.ensure(m);
  csnb_priorities<<<blocks(m), kBlock, 0, d.stream>>>(d.column.ptr, d.is_anchor.ptr, m, config.seed, d.order_alt.ptr,
                                                       d.keep.ptr);
  d.cub_call([&](void* t, std::size_t& bytes) {
    return cub::DeviceSelect::Flagged(t, bytes, d.order_alt.ptr, d.keep.ptr, d.order.ptr, d.small.ptr + 1,
                                      static_cast<int>(m), d.stream);
  });
  const std::size_t candidates = m - cubes;
  const std::uint64_t* order = d.sort_keys(d.order, d.order_alt, candidates, 32, 64);
  const int K = config.batch_size;
  const int T = config.max_neighbours;
  d.flag.ensure(candidates);
  d.pos.ensure(candidates);
  d.picked.ensure(static_cast<std::size_t>(K));
  d.result.ensure(2);
  if (d.loop_grid < 0) {
    int device = 0, cooperative = 0, sms = 0, per_sm = 0;
    STVL_CUDA(cudaGetDevice(&device));
    STVL_CUDA(cudaDeviceGetAttribute(&cooperative, cudaDevAttrCooperativeLaunch, device));
    STVL_CUDA(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device));
    STVL_CUDA(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&per_sm, csnb_loop, kLoopBlock, 0));
    d.loop_grid = cooperative && per_sm > 0 ? sms : 0;
  }
  if (d.loop_grid > 0 && candidates > 0) {
    LoopParams params{order, candidates, d.xyz.ptr, d.cube_of.ptr, d.spans.ptr, rows, layout.radius_sq,
                      d.live.ptr, d.count.ptr, T, K, d.picked.ptr};
    void* args[] = {&params};
    STVL_CUDA(cudaLaunchCooperativeKernel(reinterpret_cast<void*>(csnb_loop), dim3(d.loop_grid), dim3(kLoopBlock),
                                          args, 0, d.stream));
  }
  for (std::size_t cursor = 0; d.loop_grid == 0 && cursor < candidates;) {  // without cooperative launch
    const std::size_t window = candidates - cursor;
    csnb_flags<<<blocks(window), kBlock, 0, d.stream>>>(order + cursor, window, d.live.ptr, d.count.ptr, T, d.flag.ptr);
    d.cub_call([&](void* t, std::size_t& bytes) {
      return cub::DeviceScan::ExclusiveSum(t, bytes, d.flag.ptr, d.pos.ptr, static_cast<int>(window), d.stream);
    });
    csnb_pick<<<blocks(window), kBlock, 0, d.stream>>>(order + cursor, window, d.flag.ptr, d.pos.ptr, K, d.picked.ptr,
                                                        d.result.ptr);
    long long result[2];
    STVL_CUDA(cudaMemcpyAsync(result, d.result.ptr, sizeof(result), cudaMemcpyDeviceToHost, d.stream));
    STVL_CUDA(cudaStreamSynchronize(d.stream));
    const int batch = static_cast<int>(std::min<long long>(result[0], K));
    if (batch > 0) {
      csnb_kill<<<blocks(batch), kBlock, 0, d.stream>>>(d.picked.ptr, batch, d.live.ptr);
      csnb_decrement<<<blocks(batch), kBlock, 0, d.stream>>>(d.picked.ptr, batch, d.xyz.ptr, d.cube_of.ptr, d.spans.ptr,
                                                              rows, layout.radius_sq, d.live.ptr, d.count.ptr);
    }
    if (result[0] <= K) break;
    cursor += static_cast<std::size_t>(result[1]);
  }
  csnb_claims<<<blocks(cubes), kBlock, 0, d.stream>>>(d.anchor.ptr, cubes, d.xyz.ptr, d.spans.ptr, rows,
                                                       layout.radius_sq, d.count.ptr, T, d.is_anchor.ptr, d.live.ptr);
  F3* target = d.output_target(m, mode);
  d.cub_call([&](void* t, std::size_t& bytes) {
    return cub::DeviceSelect::Flagged(t, bytes, d.xyz.ptr, d.live.ptr, target, d.small.ptr + 1, static_cast<int>(m),
                                      d.stream);
  });
  STVL_CUDA(cudaGetLastError());
  const int kept = d.read_int(d.small.ptr + 1);
  return d.download(target, static_cast<std::size_t>(kept), mode);
}

}  // namespace stvl::filter::cuda

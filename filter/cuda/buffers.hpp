#pragma once
// The CUDA filters' shared state (filter/cuda/*.cu only): error checks, device and host buffers grown on demand,
// and Context::Impl, the stream and buffers one Context keeps between frames, with the transfers of the memory
// modes.
#include <cub/cub.cuh>

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "filter/cuda/context.hpp"
#include "filter/detail/common.hpp"

namespace stvl::filter::cuda {

inline void check(cudaError_t status, const char* what) {
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
    if (mode == MemoryMode::kManaged) cudaFree(ptr);
    else cudaFreeHost(ptr);
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
  const float* upload(const Eigen::Matrix3Xf& points, MemoryMode mode);
  // Managed memory: move the pages in one DMA instead of page faults (best effort: errors are ignored).
  void prefetch(const void* ptr, std::size_t bytes, bool to_device);
  // Where the final kernel writes `capacity` points.
  F3* output_target(std::size_t capacity, MemoryMode mode);
  Eigen::Matrix3Xf download(const F3* target, std::size_t points, MemoryMode mode);
  detail::Bounds compute_bounds(const float* p, std::size_t n);
  int read_int(const int* device);

  // Context::csnb's phases (csnb.cu). The m finite points of p[0, 3n) sorted by cube (xyz, column, key32) and the
  // cube table (cube_key, cube_begin); returns the number of cubes.
  std::uint32_t csnb_sort_into_cubes(const float* p, std::size_t n, std::uint32_t m, const detail::CsnbLayout& layout);
  // Per cube its rows' spans and its anchor (cube_of, is_anchor); every point's neighbour count, all live.
  void csnb_spans_anchors_counts(const detail::CsnbLayout& layout, std::uint32_t m, std::uint32_t cubes);
  // The m - cubes non-anchor points in their seeded random order; returns the buffer holding it.
  const std::uint64_t* csnb_random_order(std::uint32_t m, std::uint32_t cubes, std::uint64_t seed);
  // The batches of K marked points (more than T neighbours) along walk_order, deleted one after another: one
  // cooperative kernel where the device can, else a loop on the host.
  void csnb_batches(const std::uint64_t* walk_order, std::size_t candidates, int rows, float r2, int T, int K);

  template <class Fn>
  void cub_call(Fn&& fn) {
    std::size_t bytes = 0;
    STVL_CUDA(fn(nullptr, bytes));
    temp.ensure(bytes);
    STVL_CUDA(fn(temp.ptr, bytes));
  }

  // Sorts items[0, n) on bits [low, high); returns the buffer holding the result.
  std::uint64_t* sort_keys(DeviceBuffer<std::uint64_t>& a, DeviceBuffer<std::uint64_t>& b, std::size_t n, int low,
                           int high) {
    cub::DoubleBuffer<std::uint64_t> db(a.ptr, b.ptr);
    cub_call([&](void* t, std::size_t& bytes) {
      return cub::DeviceRadixSort::SortKeys(t, bytes, db, static_cast<int>(n), low, high, stream);
    });
    return db.Current();
  }
};

}  // namespace stvl::filter::cuda

#include "filter/cuda/buffers.hpp"

#include <climits>
#include <cstring>

namespace stvl::filter::cuda {

namespace {

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
  for (std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x; i < n;
       i += std::size_t(gridDim.x) * blockDim.x) {
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

}  // namespace

const float* Context::Impl::upload(const Eigen::Matrix3Xf& points, MemoryMode mode) {
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

void Context::Impl::prefetch(const void* ptr, std::size_t bytes, bool to_device) {
  if (bytes == 0) return;
  int device = 0;
  if (cudaGetDevice(&device) != cudaSuccess) return;
  cudaMemLocation location{};
  location.type = to_device ? cudaMemLocationTypeDevice : cudaMemLocationTypeHost;
  location.id = to_device ? device : 0;
  if (cudaMemPrefetchAsync(ptr, bytes, location, 0, stream) != cudaSuccess) cudaGetLastError();
}

F3* Context::Impl::output_target(std::size_t capacity, MemoryMode mode) {
  if (mode == MemoryMode::kMapped || mode == MemoryMode::kManaged) {
    host_out.ensure(capacity * 3, mode);
    return reinterpret_cast<F3*>(host_out.device_ptr);
  }
  output.ensure(capacity);
  return output.ptr;
}

Eigen::Matrix3Xf Context::Impl::download(const F3* target, std::size_t points, MemoryMode mode) {
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

detail::Bounds Context::Impl::compute_bounds(const float* p, std::size_t n) {
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

int Context::Impl::read_int(const int* device) {
  int value = 0;
  STVL_CUDA(cudaMemcpyAsync(&value, device, sizeof(int), cudaMemcpyDeviceToHost, stream));
  STVL_CUDA(cudaStreamSynchronize(stream));
  return value;
}

}  // namespace stvl::filter::cuda

// CUDA CSNB. Same steps and arithmetic as csnb.cpp (filter/detail/shared.hpp), so the output is bit-identical
// to the CPU's.
#include <cooperative_groups.h>

#include "filter/cuda/buffers.hpp"

namespace stvl::filter::cuda {

namespace {

__global__ void csnb_keys(const float* p, std::size_t n, detail::CsnbLayout layout, int index_bits,
                          std::uint64_t* items) {
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

std::uint32_t Context::Impl::csnb_sort_into_cubes(const float* p, std::size_t n, std::uint32_t m,
                                                  const detail::CsnbLayout& layout) {
  const int index_bits = std::max(1, detail::bit_width(n - 1));
  const int key_bits = 3 * layout.grid_exponent;
  items.ensure(n);
  items_alt.ensure(n);
  csnb_keys<<<blocks(n), kBlock, 0, stream>>>(p, n, layout, index_bits, items.ptr);
  const std::uint64_t* sorted = sort_keys(items, items_alt, n, index_bits, std::min(64, index_bits + key_bits + 1));
  xyz.ensure(m);
  column.ensure(m);
  key32.ensure(m);
  csnb_gather<<<blocks(m), kBlock, 0, stream>>>(p, sorted, m, index_bits, xyz.ptr, column.ptr, key32.ptr);
  cube_key.ensure(m);
  cube_count.ensure(m);
  cube_begin.ensure(m + 1);
  small.ensure(2);
  cub_call([&](void* t, std::size_t& bytes) {
    return cub::DeviceRunLengthEncode::Encode(t, bytes, key32.ptr, cube_key.ptr, cube_count.ptr, small.ptr,
                                              static_cast<int>(m), stream);
  });
  const std::uint32_t cubes = static_cast<std::uint32_t>(read_int(small.ptr));
  cub_call([&](void* t, std::size_t& bytes) {
    return cub::DeviceScan::ExclusiveSum(t, bytes, cube_count.ptr, cube_begin.ptr, static_cast<int>(cubes), stream);
  });
  STVL_CUDA(cudaMemcpyAsync(cube_begin.ptr + cubes, &m, sizeof(m), cudaMemcpyHostToDevice, stream));
  return cubes;
}

void Context::Impl::csnb_spans_anchors_counts(const detail::CsnbLayout& layout, std::uint32_t m, std::uint32_t cubes) {
  const int rows = detail::csnb_rows(layout);
  spans.ensure(std::size_t(cubes) * rows * 2);
  anchor.ensure(cubes);
  cube_of.ensure(m);
  is_anchor.ensure(m);
  live.ensure(m);
  count.ensure(m);
  csnb_cubes<<<blocks(cubes), kBlock, 0, stream>>>(layout, cube_key.ptr, cube_begin.ptr, cubes, xyz.ptr, spans.ptr,
                                                   anchor.ptr, cube_of.ptr, is_anchor.ptr);
  csnb_mark_anchors<<<blocks(cubes), kBlock, 0, stream>>>(anchor.ptr, cubes, is_anchor.ptr);
  csnb_count<<<blocks(m), kBlock, 0, stream>>>(xyz.ptr, m, cube_of.ptr, spans.ptr, rows, layout.radius_sq, count.ptr,
                                               live.ptr);
}

const std::uint64_t* Context::Impl::csnb_random_order(std::uint32_t m, std::uint32_t cubes, std::uint64_t seed) {
  order.ensure(m);
  order_alt.ensure(m);
  keep.ensure(m);
  csnb_priorities<<<blocks(m), kBlock, 0, stream>>>(column.ptr, is_anchor.ptr, m, seed, order_alt.ptr, keep.ptr);
  cub_call([&](void* t, std::size_t& bytes) {
    return cub::DeviceSelect::Flagged(t, bytes, order_alt.ptr, keep.ptr, order.ptr, small.ptr + 1, static_cast<int>(m),
                                      stream);
  });
  return sort_keys(order, order_alt, m - cubes, 32, 64);
}

void Context::Impl::csnb_batches(const std::uint64_t* walk_order, std::size_t candidates, int rows, float r2, int T,
                                 int K) {
  flag.ensure(candidates);
  pos.ensure(candidates);
  picked.ensure(static_cast<std::size_t>(K));
  result.ensure(2);
  if (loop_grid < 0) {
    int device = 0, cooperative = 0, sms = 0, per_sm = 0;
    STVL_CUDA(cudaGetDevice(&device));
    STVL_CUDA(cudaDeviceGetAttribute(&cooperative, cudaDevAttrCooperativeLaunch, device));
    STVL_CUDA(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device));
    STVL_CUDA(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&per_sm, csnb_loop, kLoopBlock, 0));
    loop_grid = cooperative && per_sm > 0 ? sms : 0;
  }
  if (loop_grid > 0 && candidates > 0) {
    LoopParams params{walk_order, candidates, xyz.ptr,   cube_of.ptr, spans.ptr, rows,
                      r2,         live.ptr,   count.ptr, T,           K,         picked.ptr};
    void* args[] = {&params};
    STVL_CUDA(cudaLaunchCooperativeKernel(reinterpret_cast<void*>(csnb_loop), dim3(loop_grid), dim3(kLoopBlock), args,
                                          0, stream));
  }
  for (std::size_t cursor = 0; loop_grid == 0 && cursor < candidates;) {  // without cooperative launch
    const std::size_t window = candidates - cursor;
    csnb_flags<<<blocks(window), kBlock, 0, stream>>>(walk_order + cursor, window, live.ptr, count.ptr, T, flag.ptr);
    cub_call([&](void* t, std::size_t& bytes) {
      return cub::DeviceScan::ExclusiveSum(t, bytes, flag.ptr, pos.ptr, static_cast<int>(window), stream);
    });
    csnb_pick<<<blocks(window), kBlock, 0, stream>>>(walk_order + cursor, window, flag.ptr, pos.ptr, K, picked.ptr,
                                                     result.ptr);
    long long found[2];
    STVL_CUDA(cudaMemcpyAsync(found, result.ptr, sizeof(found), cudaMemcpyDeviceToHost, stream));
    STVL_CUDA(cudaStreamSynchronize(stream));
    const int batch = static_cast<int>(std::min<long long>(found[0], K));
    if (batch > 0) {
      csnb_kill<<<blocks(batch), kBlock, 0, stream>>>(picked.ptr, batch, live.ptr);
      csnb_decrement<<<blocks(batch), kBlock, 0, stream>>>(picked.ptr, batch, xyz.ptr, cube_of.ptr, spans.ptr, rows, r2,
                                                           live.ptr, count.ptr);
    }
    if (found[0] <= K) break;
    cursor += static_cast<std::size_t>(found[1]);
  }
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
  const std::uint32_t cubes = d.csnb_sort_into_cubes(p, n, m, layout);
  d.csnb_spans_anchors_counts(layout, m, cubes);
  // Random order of the non-anchor points (see csnb.cpp for why one order serves every batch).
  const std::uint64_t* order = d.csnb_random_order(m, cubes, config.seed);
  const int rows = detail::csnb_rows(layout);
  const int T = config.max_neighbours;
  d.csnb_batches(order, m - cubes, rows, layout.radius_sq, T, config.batch_size);
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

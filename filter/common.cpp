#include "filter/detail/common.hpp"

#include <atomic>
#include <cmath>
#include <condition_variable>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>

#if STVL_FILTER_TBB
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>
#endif

namespace stvl::filter::detail {

namespace {
std::string format(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}
#if !STVL_FILTER_TBB
void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

// Persistent workers for run_parallel: a call publishes (fn, context, parts) under a generation number;
// workers and the caller claim parts through one atomic counter tagged with that generation, so a worker
// late from an earlier call can never take a part of a later one.
class Pool {
 public:
  ~Pool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
      generation_.fetch_add(1);
    }
    wake_.notify_all();
    for (auto& worker : workers_) worker.join();
  }

  bool try_run(int parts, void (*fn)(void*, int), void* context) {
    std::unique_lock<std::mutex> call(call_, std::try_to_lock);
    if (!call.owns_lock()) return false;
    while (static_cast<int>(workers_.size()) < parts - 1) {
      workers_.emplace_back([this] { loop(); });
    }
    std::uint64_t generation;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      fn_ = fn;
      context_ = context;
      parts_ = parts;
      pending_.store(parts);
      generation = generation_.load() + 1;
      next_.store(generation << 32);
      generation_.store(generation);
    }
    wake_.notify_all();
    work(generation, fn, context, parts);
    for (int spin = 0; pending_.load(std::memory_order_acquire) != 0; ++spin) {
      if (spin < 20000) {
        cpu_relax();
        continue;
      }
      std::unique_lock<std::mutex> lock(mutex_);
      done_.wait(lock, [this] { return pending_.load() == 0; });
    }
    return true;
  }

 private:
  void work(std::uint64_t generation, void (*fn)(void*, int), void* context, int parts) {
    for (;;) {
      std::uint64_t v = next_.load();
      do {
        if ((v >> 32) != generation || static_cast<int>(v & 0xFFFFFFFFu) >= parts) return;
      } while (!next_.compare_exchange_weak(v, v + 1));
      fn(context, static_cast<int>(v & 0xFFFFFFFFu));
      if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
        std::lock_guard<std::mutex> lock(mutex_);
        done_.notify_all();
      }
    }
  }

  void loop() {
    std::uint64_t seen = generation_.load();
    for (;;) {
      for (int spin = 0; spin < 20000 && generation_.load(std::memory_order_acquire) == seen; ++spin) cpu_relax();
      void (*fn)(void*, int);
      void* context;
      int parts;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || generation_.load() != seen; });
        if (stop_) return;
        seen = generation_.load();
        fn = fn_;
        context = context_;
        parts = parts_;
      }
      work(seen, fn, context, parts);
    }
  }

  std::mutex call_, mutex_;
  std::condition_variable wake_, done_;
  std::vector<std::thread> workers_;
  std::atomic<std::uint64_t> generation_{0}, next_{0};
  std::atomic<int> pending_{0};
  void (*fn_)(void*, int) = nullptr;
  void* context_ = nullptr;
  int parts_ = 0;
  bool stop_ = false;
};

#endif
}  // namespace

void run_parallel(int parts, void (*fn)(void*, int), void* context) {
  if (parts <= 1) {
    if (parts == 1) fn(context, 0);
    return;
  }
#if STVL_FILTER_TBB
  // One task per part. Isolated: while this thread waits for the parts it runs none but these, never an outer
  // task that could enter a filter again on this thread (and its thread_local buffers).
  tbb::this_task_arena::isolate([&] {
    tbb::parallel_for(
        tbb::blocked_range<int>(0, parts, 1),
        [&](const tbb::blocked_range<int>& range) {
          for (int t = range.begin(); t != range.end(); ++t) fn(context, t);
        },
        tbb::simple_partitioner());
  });
#else
  static Pool pool;
  if (pool.try_run(parts, fn, context)) return;
  std::vector<std::thread> spawned;
  spawned.reserve(parts - 1);
  for (int t = 0; t + 1 < parts; ++t) spawned.emplace_back([fn, context, t] { fn(context, t); });
  fn(context, parts - 1);
  for (auto& thread : spawned) thread.join();
#endif
}

void validate(const VoxelGridConfig& config) {
  if (!std::isfinite(config.voxel_size_m) || config.voxel_size_m <= 0.0) {
    throw std::invalid_argument("voxel grid: voxel_size_m must be finite and > 0, got " + format(config.voxel_size_m));
  }
  if (config.min_points_per_voxel < 0) {
    throw std::invalid_argument("voxel grid: min_points_per_voxel must be >= 0, got " +
                                std::to_string(config.min_points_per_voxel));
  }
}

void validate(const CsnbConfig& config) {
  if (!std::isfinite(config.voxel_size_m) || config.voxel_size_m <= 0.0) {
    throw std::invalid_argument("csnb: voxel_size_m must be finite and > 0, got " + format(config.voxel_size_m));
  }
  if (config.max_neighbours < 0) {
    throw std::invalid_argument("csnb: max_neighbours must be >= 0, got " + std::to_string(config.max_neighbours));
  }
  if (config.batch_size < 1) {
    throw std::invalid_argument("csnb: batch_size must be >= 1, got " + std::to_string(config.batch_size));
  }
  if (config.grid_exponent != 0 && (config.grid_exponent < 4 || config.grid_exponent > 9)) {
    throw std::invalid_argument("csnb: grid_exponent must be 0 (auto) or 4..9, got " +
                                std::to_string(config.grid_exponent));
  }
}

void check_cloud_size(std::int64_t points) {
  if (points >= std::int64_t{std::numeric_limits<std::uint32_t>::max()}) {
    throw std::invalid_argument("filter: clouds are limited to 2^32-1 points, got " + std::to_string(points));
  }
}

int bit_width(std::uint64_t value) {
  int bits = 0;
  while (value != 0) {
    ++bits;
    value >>= 1;
  }
  return bits;
}

namespace {
std::atomic<bool> g_simd_enabled{true};
}  // namespace

void set_simd_enabled(bool enabled) { g_simd_enabled = enabled; }
bool simd_enabled() { return g_simd_enabled; }

bool cpu_has_avx2() {
#if defined(__x86_64__) || defined(__i386__)
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

int resolve_threads(int threads) {
  if (threads > 0) return threads;
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

VoxelLayout make_voxel_layout(const Bounds& bounds, double voxel_size_m, std::uint64_t points) {
  VoxelLayout layout;
  layout.voxel_size_m = voxel_size_m;
  constexpr double kLimit = 4.0e18;  // |floor(x / voxel)| must fit an int64 with room for differences
  std::uint64_t total = 1;
  bool overflow = false;
  for (int a = 0; a < 3; ++a) {
    const double lo = std::floor(double(bounds.min[a]) / voxel_size_m);
    const double hi = std::floor(double(bounds.max[a]) / voxel_size_m);
    if (!(std::fabs(lo) < kLimit && std::fabs(hi) < kLimit)) {
      overflow = true;
      break;
    }
    layout.base[a] = static_cast<std::int64_t>(lo);
    layout.dims[a] = static_cast<std::uint64_t>(static_cast<std::int64_t>(hi) - layout.base[a]) + 1;
    if (__builtin_mul_overflow(total, layout.dims[a], &total)) {
      overflow = true;
      break;
    }
  }
  if (overflow) {
    std::ostringstream out;
    out << "voxel grid: the cloud's bounding box (" << double(bounds.max[0]) - bounds.min[0] << " x "
        << double(bounds.max[1]) - bounds.min[1] << " x " << double(bounds.max[2]) - bounds.min[2]
        << " m) at voxel_size_m=" << voxel_size_m
        << " needs more voxels than a 64-bit key holds; use a larger voxel_size_m";
    throw std::invalid_argument(out.str());
  }
  layout.key_bits = bit_width(total - 1);
  layout.index_bits = bit_width(points > 0 ? points - 1 : 0);
  layout.packed = layout.key_bits + layout.index_bits <= 64;
  return layout;
}

CsnbLayout make_csnb_layout(const Bounds& bounds, const CsnbConfig& config) {
  CsnbLayout layout;
  double extent = 0.0;
  for (int a = 0; a < 3; ++a) {
    layout.min_m[a] = bounds.min[a];
    extent = std::max(extent, double(bounds.max[a]) - double(bounds.min[a]));
  }
  const double d = config.voxel_size_m;
  // The [-1,1]^3 normalisation is scaled so that a cube is exactly d (the grid may overhang the cloud);
  // when the extent needs more than 2^9 cubes of d, the cube grows to extent / 2^9: the 27-cube search
  // still covers the radius, so the density bound stays exact, only the candidates per point grow.
  int n = config.grid_exponent;
  if (n == 0) {
    layout.cube_edge_m = std::max(d, extent / 512.0);
    n = std::clamp(static_cast<int>(std::ceil(std::log2(std::max(extent / layout.cube_edge_m, 1.0)))), 4, 9);
  } else {
    layout.cube_edge_m = extent > 0.0 ? extent / double(1u << n) : d;  // given n: the paper's exact fit
  }
  layout.grid_exponent = n;
  const double reach = std::ceil(d / layout.cube_edge_m);
  layout.reach = static_cast<int>(std::clamp(reach, 1.0, double((1u << n) - 1)));
  layout.radius_sq = static_cast<float>(d * d);
  return layout;
}

namespace {

// Bounds of points [b, e) of p, skipping points with a non-finite coordinate.
Bounds bounds_of(const float* p, std::size_t b, std::size_t e) {
  Bounds part;
  for (int a = 0; a < 3; ++a) {
    part.min[a] = std::numeric_limits<float>::infinity();
    part.max[a] = -std::numeric_limits<float>::infinity();
  }
  for (std::size_t i = b; i < e; ++i) {
    const float x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
    if (!finite3(x, y, z)) continue;
    ++part.finite;
    part.min[0] = std::min(part.min[0], x);
    part.max[0] = std::max(part.max[0], x);
    part.min[1] = std::min(part.min[1], y);
    part.max[1] = std::max(part.max[1], y);
    part.min[2] = std::min(part.min[2], z);
    part.max[2] = std::max(part.max[2], z);
  }
  return part;
}

// The same, for blocks of 4 points (12 floats) at a time without a branch per point, which the compiler
// vectorises: each of the 12 lanes keeps the min and max of its own coordinate. A block holding a non-finite
// value (x - x is not 0) is redone by bounds_of.
Bounds bounds_of_blocks(const float* p, std::size_t b, std::size_t e) {
  constexpr std::size_t kPoints = 4, kLanes = 3 * kPoints, kBlock = 1024;
  Bounds part = bounds_of(p, b, b + (e - b) % kPoints);
  float lo[kLanes], hi[kLanes];
  for (std::size_t k = 0; k < kLanes; ++k) {
    lo[k] = part.min[k % 3];
    hi[k] = part.max[k % 3];
  }
  for (std::size_t i = b + (e - b) % kPoints; i < e;) {
    const std::size_t end = std::min(e, i + kBlock);
    float block_lo[kLanes], block_hi[kLanes];
    std::copy(lo, lo + kLanes, block_lo);
    std::copy(hi, hi + kLanes, block_hi);
    float bad = 0.f;
    for (const float* q = p + 3 * i; q != p + 3 * end; q += kLanes) {
      for (std::size_t k = 0; k < kLanes; ++k) {
        block_lo[k] = q[k] < block_lo[k] ? q[k] : block_lo[k];
        block_hi[k] = q[k] > block_hi[k] ? q[k] : block_hi[k];
        bad = (q[k] - q[k] == 0.f) ? bad : 1.f;
      }
    }
    if (bad == 0.f) {
      std::copy(block_lo, block_lo + kLanes, lo);
      std::copy(block_hi, block_hi + kLanes, hi);
      part.finite += end - i;
    } else {
      const Bounds some = bounds_of(p, i, end);
      part.finite += some.finite;
      for (std::size_t k = 0; k < kLanes; ++k) {
        lo[k] = std::min(lo[k], some.min[k % 3]);
        hi[k] = std::max(hi[k], some.max[k % 3]);
      }
    }
    i = end;
  }
  for (std::size_t k = 0; k < kLanes; ++k) {
    part.min[k % 3] = std::min(part.min[k % 3], lo[k]);
    part.max[k % 3] = std::max(part.max[k % 3], hi[k]);
  }
  return part;
}

}  // namespace

Bounds compute_bounds(const Eigen::Matrix3Xf& points, int threads) {
  const std::size_t n = static_cast<std::size_t>(points.cols());
  threads = parts_for(n, threads);
  std::vector<Bounds> parts(static_cast<std::size_t>(threads));
  const float* p = points.data();
  parallel_for(n, threads, [&](std::size_t b, std::size_t e, int t) { parts[t] = bounds_of_blocks(p, b, e); });
  Bounds all = parts[0];
  for (std::size_t t = 1; t < parts.size(); ++t) {
    if (parts[t].finite == 0) continue;
    if (all.finite == 0) {
      all = parts[t];
      continue;
    }
    all.finite += parts[t].finite;
    for (int a = 0; a < 3; ++a) {
      all.min[a] = std::min(all.min[a], parts[t].min[a]);
      all.max[a] = std::max(all.max[a], parts[t].max[a]);
    }
  }
  return all;
}

}  // namespace stvl::filter::detail

#include "filter/voxel_grid.hpp"

#include <cstring>

#include "filter/detail/common.hpp"

namespace stvl::filter {

namespace {

// The voxel grid in three steps, each parallel over contiguous parts:
// 1. runs: consecutive finite points with the same voxel (depth clouds in pixel order have many) become one
//    entry (key, first point index); run_end[first] holds the index past its last point;
// 2. a stable LSD radix sort of the entries on the key bits only (entries are produced in index order);
// 3. reduce: each part takes whole keys and sums the points of each key run by run, which is index order,
//    so the double sums match a point-by-point sum in index order (and the CUDA kernel) bit for bit.
struct KeyIndex {
  std::uint64_t key;
  std::uint64_t index;
};

// Buffers kept between calls by each calling thread (clouds up to kRetainPoints; larger ones allocate).
struct Workspace {
  std::vector<std::uint64_t> items, scratch;
  std::vector<KeyIndex> pairs, pairs_scratch;
  std::vector<std::uint32_t> run_end;
  std::vector<float> centroids;
};
constexpr std::size_t kRetainPoints = std::size_t{1} << 22;

template <class V>
void ensure(std::vector<V>& v, std::size_t n) {
  if (v.size() < n) v.resize(n);
}

// T: the entry type; make_entry(key, index) builds one, key_of / index_of read it back, sort_key gives the
// bits sorted on ([low_bit, low_bit + key_bits)).
template <class T, class MakeEntry, class KeyOf, class IndexOf, class SortKey>
Eigen::Matrix3Xf voxel_grid_impl(const float* p, std::size_t n, const detail::VoxelLayout& layout,
                                 std::size_t min_points, int threads, std::vector<T>& items,
                                 std::vector<T>& scratch, Workspace& w, int low_bit, MakeEntry make_entry,
                                 KeyOf key_of, IndexOf index_of, SortKey sort_key) {
  ensure(items, n);
  ensure(scratch, n);
  ensure(w.run_end, n);
  std::uint32_t* run_end = w.run_end.data();
  const int parts = detail::parts_for(n, threads, 16384);
  std::vector<detail::Segment<T>> segments(parts);
  T* entries = items.data();
  detail::parallel_for(n, parts, [&](std::size_t b, std::size_t e, int t) {
    T* out = entries + b;
    std::size_t count = 0;
    std::uint64_t current = 0;
    std::uint32_t run_begin = 0;
    bool in_run = false;
    for (std::size_t i = b; i < e; ++i) {
      const float x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
      if (!detail::finite3(x, y, z)) {
        if (in_run) run_end[run_begin] = static_cast<std::uint32_t>(i);
        in_run = false;
        continue;
      }
      const std::uint64_t key = detail::voxel_key(layout, x, y, z);
      if (in_run && key == current) continue;
      if (in_run) run_end[run_begin] = static_cast<std::uint32_t>(i);
      out[count++] = make_entry(key, i);
      current = key;
      run_begin = static_cast<std::uint32_t>(i);
      in_run = true;
    }
    if (in_run) run_end[run_begin] = static_cast<std::uint32_t>(e);
    segments[t] = {out, count};
  });
  std::size_t runs = 0;
  for (const auto& s : segments) runs += s.size;
  const T* sorted = detail::radix_sort_segments(
      segments, items.data(), scratch.data(), low_bit, low_bit + layout.key_bits, sort_key, threads);

  // Reduce: parts aligned to key boundaries, centroids written at the part's first entry, then compacted.
  const int rparts = detail::parts_for(runs, threads, 16384);
  std::vector<std::size_t> begin(rparts + 1, runs), kept(rparts, 0);
  for (int t = 0; t < rparts; ++t) {
    std::size_t b = runs * std::size_t(t) / std::size_t(rparts);
    while (b > 0 && b < runs && key_of(sorted[b]) == key_of(sorted[b - 1])) ++b;
    begin[t] = b;
  }
  for (int t = 1; t < rparts; ++t) begin[t] = std::max(begin[t], begin[t - 1]);
  ensure(w.centroids, 3 * runs);
  float* c = w.centroids.data();
  detail::parallel_for(std::size_t(rparts), rparts, [&](std::size_t, std::size_t, int t) {
    float* o = c + 3 * begin[t];
    std::size_t v = 0;
    for (std::size_t i = begin[t]; i < begin[t + 1];) {
      const std::uint64_t k = key_of(sorted[i]);
      double sx = 0, sy = 0, sz = 0;
      std::size_t count = 0;
      do {
        const std::uint32_t first = static_cast<std::uint32_t>(index_of(sorted[i]));
        const std::uint32_t last = run_end[first];
        count += last - first;
        for (const float* q = p + 3 * std::size_t(first); q != p + 3 * std::size_t(last); q += 3) {
          sx += q[0];
          sy += q[1];
          sz += q[2];
        }
        ++i;
      } while (i < begin[t + 1] && key_of(sorted[i]) == k);
      if (count < min_points) continue;
      const double d = double(count);
      o[3 * v] = static_cast<float>(sx / d);
      o[3 * v + 1] = static_cast<float>(sy / d);
      o[3 * v + 2] = static_cast<float>(sz / d);
      ++v;
    }
    kept[t] = v;
  });
  std::size_t total = 0;
  for (int t = 0; t < rparts; ++t) total += kept[t];
  Eigen::Matrix3Xf out(3, static_cast<Eigen::Index>(total));
  float* o = out.data();
  for (int t = 0; t < rparts; ++t) {
    if (kept[t]) std::memcpy(o, c + 3 * begin[t], kept[t] * 3 * sizeof(float));
    o += 3 * kept[t];
  }
  return out;
}

}  // namespace

Eigen::Matrix3Xf voxel_grid(const Eigen::Matrix3Xf& points, const VoxelGridConfig& config, int threads) {
  detail::validate(config);
  detail::check_cloud_size(points.cols());
  threads = detail::resolve_threads(threads);
  const detail::Bounds bounds = detail::compute_bounds(points, threads);
  if (bounds.finite == 0) return Eigen::Matrix3Xf(3, 0);
  const std::size_t n = static_cast<std::size_t>(points.cols());
  const detail::VoxelLayout layout = detail::make_voxel_layout(bounds, config.voxel_size_m, n);
  const std::size_t min_points = static_cast<std::size_t>(std::max(config.min_points_per_voxel, 1));
  const float* p = points.data();

  thread_local Workspace retained;
  Workspace local;
  Workspace& w = n <= kRetainPoints ? retained : local;

  if (layout.packed) {
    // Entry = key << index_bits | first index of the run.
    const int shift = layout.index_bits;
    const std::uint64_t index_mask = (std::uint64_t{1} << shift) - 1;
    return voxel_grid_impl(
        p, n, layout, min_points, threads, w.items, w.scratch, w, shift,
        [shift](std::uint64_t key, std::size_t i) { return key << shift | i; },
        [shift](std::uint64_t v) { return v >> shift; }, [index_mask](std::uint64_t v) { return v & index_mask; },
        [](std::uint64_t v) { return v; });
  }
  return voxel_grid_impl(
      p, n, layout, min_points, threads, w.pairs, w.pairs_scratch, w, 0,
      [](std::uint64_t key, std::size_t i) { return KeyIndex{key, i}; }, [](const KeyIndex& v) { return v.key; },
      [](const KeyIndex& v) { return v.index; }, [](const KeyIndex& v) { return v.key; });
}

}  // namespace stvl::filter

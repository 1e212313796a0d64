#include "filter/voxel_grid.hpp"

#include "filter/detail/common.hpp"

namespace stvl::filter {

namespace {

struct KeyIndex {
  std::uint64_t key;
  std::uint32_t index;
};

// Sorted entries -> centroids of runs of equal key, each part of the array handled by one thread, into its
// own buffer (one pass), then copied into place.
template <class T, class KeyFn, class IndexFn>
Eigen::Matrix3Xf reduce_runs(const std::vector<T>& sorted, KeyFn key, IndexFn index, const float* p,
                             std::size_t min_points, int threads) {
  const std::size_t n = sorted.size();
  threads = detail::parts_for(n, threads);
  std::vector<std::size_t> begin(threads + 1, n), kept(threads + 1, 0);
  for (int t = 0; t < threads; ++t) {
    std::size_t b = n * t / threads;
    while (b > 0 && b < n && key(sorted[b]) == key(sorted[b - 1])) ++b;
    begin[t] = b;
  }
  thread_local std::vector<std::vector<float>> buffers_workspace;
  std::vector<std::vector<float>>& buffers = buffers_workspace;  // the caller's, seen by the pool's workers
  if (static_cast<int>(buffers.size()) < threads) buffers.resize(threads);
  const detail::AtScopeExit release{[&] {
    if (n > detail::kKeepBuffersUpToPoints) buffers.clear();
  }};
  detail::parallel_for(threads, threads, [&](std::size_t, std::size_t, int t) {
    std::vector<float>& o = buffers[t];
    o.clear();
    constexpr std::size_t kAhead = 16;  // the points of a voxel are scattered over the cloud: prefetch them
    for (std::size_t i = begin[t]; i < begin[t + 1];) {
      const std::uint64_t k = key(sorted[i]);
      double sx = 0, sy = 0, sz = 0;
      std::size_t j = i;
      for (; j < n && key(sorted[j]) == k; ++j) {
        if (j + kAhead < n) __builtin_prefetch(p + 3 * index(sorted[j + kAhead]));
        const std::size_t q = index(sorted[j]);
        sx += p[3 * q];
        sy += p[3 * q + 1];
        sz += p[3 * q + 2];
      }
      if (j - i >= min_points) {
        const double c = double(j - i);
        o.push_back(static_cast<float>(sx / c));
        o.push_back(static_cast<float>(sy / c));
        o.push_back(static_cast<float>(sz / c));
      }
      i = j;
    }
    kept[t + 1] = o.size() / 3;
  });
  for (int t = 0; t < threads; ++t) kept[t + 1] += kept[t];
  Eigen::Matrix3Xf out(3, static_cast<Eigen::Index>(kept[threads]));
  detail::parallel_for(threads, threads, [&](std::size_t, std::size_t, int t) {
    std::copy(buffers[t].begin(), buffers[t].end(), out.data() + 3 * kept[t]);
  });
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

  // Where each part of the cloud starts among the finite points.
  const int parts = detail::parts_for(n, threads);
  std::vector<std::size_t> offset(parts + 1, 0);
  if (bounds.finite != n) {
    detail::parallel_for(n, parts, [&](std::size_t b, std::size_t e, int t) {
      std::size_t c = 0;
      for (std::size_t i = b; i < e; ++i) c += detail::finite3(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
      offset[t + 1] = c;
    });
  } else {
    for (int t = 0; t < parts; ++t) offset[t + 1] = n * (t + 1) / parts - n * t / parts;
  }
  for (int t = 0; t < parts; ++t) offset[t + 1] += offset[t];

  // Finite points as sort items, in index order, each thread writing its own slice; a stable sort on the key
  // bits only (a packed item's index bits are already in order), then the centroids of equal keys.
  auto sort_and_reduce = [&](auto make_item, auto key, auto index) {
    using Item = decltype(make_item(std::uint64_t{}, std::uint32_t{}));
    // Kept per calling thread: a fresh multi-megabyte vector per frame costs tens of thousands of page faults.
    // Named through references, since the pool's workers must see the caller's vectors, not their own.
    thread_local std::vector<Item> items_workspace, scratch_workspace;
    std::vector<Item>& items = items_workspace;
    std::vector<Item>& scratch = scratch_workspace;
    const detail::AtScopeExit release{[&] {
      if (n > detail::kKeepBuffersUpToPoints) items = {}, scratch = {};
    }};
    items.resize(bounds.finite);
    detail::parallel_for(n, parts, [&](std::size_t b, std::size_t e, int t) {
      std::size_t o = offset[t];
      for (std::size_t i = b; i < e; ++i) {
        const float x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
        if (!detail::finite3(x, y, z)) continue;
        items[o++] = make_item(detail::voxel_key(layout, x, y, z), static_cast<std::uint32_t>(i));
      }
    });
    detail::radix_sort(items, scratch, 0, layout.key_bits, key, threads);
    return reduce_runs(items, key, index, p, min_points, threads);
  };
  if (layout.packed) {
    const int shift = layout.index_bits;
    const std::uint64_t index_mask = shift == 64 ? ~0ull : (std::uint64_t{1} << shift) - 1;
    return sort_and_reduce(
        [shift](std::uint64_t key, std::uint32_t i) { return (shift == 64 ? 0 : key << shift) | i; },
        [shift](std::uint64_t v) { return shift == 64 ? 0 : v >> shift; },
        [index_mask](std::uint64_t v) { return v & index_mask; });
  }
  return sort_and_reduce([](std::uint64_t key, std::uint32_t i) { return KeyIndex{key, i}; },
                         [](const KeyIndex& v) { return v.key; }, [](const KeyIndex& v) { return v.index; });
}

}  // namespace stvl::filter

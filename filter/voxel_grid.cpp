#include "filter/voxel_grid.hpp"

#include "filter/detail/common.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <type_traits>

namespace stvl::filter {

namespace {

// Items carry their point, so that the centroids are summed from the bucketed items in order instead of
// gathering each voxel's points from all over the cloud. 32-bit keys whenever the bounding box allows.
template <class Key>
struct KeyPoint {
  Key key;
  float xyz[3];
};

// Voxels that differ only in this many low key bits are summed in a direct-address table (28 KiB: in L1).
constexpr int kDirectBits = 10;
// Buckets of a most-significant-digit pass: few enough that the scatter's write positions stay in L1.
constexpr int kBucketBits = 8;
// The first pass (over the whole cloud, in parallel) may use up to 2^kFirstPassBits buckets: a depth camera's cloud
// (keys of about 20 bits at 5 cm) then goes from its buckets straight to the direct table.
constexpr int kFirstPassBits = 12;
// Buckets of at most this many points are sorted by insertion instead.
constexpr std::size_t kInsertionPoints = 24;

// Voxel keys of points that are all finite, with voxel indices that fit int32 and keys that fit 32 bits: the
// same values as detail::voxel_key (the same division and floor) without a branch per point, in a loop the
// compiler vectorises; on x86 it is compiled for AVX2 and used where the CPU has it (4 divisions at a time).
// detail::voxel_key's 64-bit floor_div would not vectorise: AVX2 converts double to int32, not to int64.
struct Keys32 {
  double voxel_size_m;
  std::int32_t base[3];
  std::uint32_t dims[2];
};

bool make_keys32(const detail::VoxelLayout& l, Keys32& k) {
  constexpr std::int64_t lo = std::numeric_limits<std::int32_t>::min(), hi = std::numeric_limits<std::int32_t>::max();
  if (l.key_bits > 32) return false;
  for (int a = 0; a < 3; ++a) {
    if (l.base[a] < lo || l.base[a] + std::int64_t(l.dims[a]) - 1 > hi) return false;
    k.base[a] = static_cast<std::int32_t>(l.base[a]);
  }
  k.voxel_size_m = l.voxel_size_m;
  k.dims[0] = static_cast<std::uint32_t>(l.dims[0]);
  k.dims[1] = static_cast<std::uint32_t>(l.dims[1]);
  return true;
}

#if defined(__x86_64__) || defined(__i386__)
#define STVL_KEYS32_TARGET __attribute__((target("avx2")))
bool keys32_supported() { return detail::cpu_has_avx2() && detail::simd_enabled(); }
#else
#define STVL_KEYS32_TARGET
bool keys32_supported() { return detail::simd_enabled(); }
#endif

STVL_KEYS32_TARGET void keys32(const float* p, std::size_t n, const Keys32 l, std::uint32_t* keys) {
  // In range by construction: every finite point lies in the bounding box the layout was made from, and the
  // rounded division is monotonic, so floor(v / size) is within [base, base + dims - 1].
  auto axis = [&](float v, int a) {
    const double q = double(v) / l.voxel_size_m;
    const std::int32_t t = static_cast<std::int32_t>(q);
    return static_cast<std::uint32_t>(t - (static_cast<double>(t) > q) - l.base[a]);
  };
  for (std::size_t i = 0; i < n; ++i) {
    keys[i] = axis(p[3 * i], 0) + l.dims[0] * (axis(p[3 * i + 1], 1) + l.dims[1] * axis(p[3 * i + 2], 2));
  }
}

// Sums of the voxels of one bucket, indexed by the key's low bits; all zero between buckets.
struct Table {
  std::vector<std::uint32_t> count = std::vector<std::uint32_t>(std::size_t{1} << kDirectBits, 0);
  std::vector<std::array<double, 3>> sum = std::vector<std::array<double, 3>>(std::size_t{1} << kDirectBits);
  // The slots in first-touch order; one spare entry, written (not counted) by every point after all are touched.
  std::vector<std::uint32_t> touched = std::vector<std::uint32_t>((std::size_t{1} << kDirectBits) + 1);
};

// Kept per calling thread between calls: fresh multi-megabyte buffers would page-fault on every frame.
template <class Key>
struct Workspace {
  std::vector<Key> keys;                            // of the finite points, in index order
  std::vector<KeyPoint<Key>> items;                 // grouped by bucket (the key's high bits)
  std::vector<std::vector<KeyPoint<Key>>> scratch;  // per worker, for splitting one bucket
  std::vector<Table> tables;                        // per worker
  std::vector<std::vector<float>> centroids;        // per worker, x y z
};

// One voxel's centroid, appended to `out` when it has at least min_points points. Every path of the reduction
// ends here, so all of them round alike.
inline void append_centroid(double sx, double sy, double sz, std::size_t count, std::size_t min_points,
                            std::vector<float>& out) {
  if (count < min_points) return;
  const double c = double(count);
  out.push_back(static_cast<float>(sx / c));
  out.push_back(static_cast<float>(sy / c));
  out.push_back(static_cast<float>(sz / c));
}

// The centroids (double sums in order) of the runs of equal key in sorted[0, m), appended to `out`.
template <class Item>
void append_centroids(const Item* sorted, std::size_t m, std::size_t min_points, std::vector<float>& out) {
  for (std::size_t i = 0; i < m;) {
    const auto k = sorted[i].key;
    double sx = 0, sy = 0, sz = 0;
    std::size_t j = i;
    for (; j < m && sorted[j].key == k; ++j) {
      sx += sorted[j].xyz[0];
      sy += sorted[j].xyz[1];
      sz += sorted[j].xyz[2];
    }
    append_centroid(sx, sy, sz, j - i, min_points, out);
    i = j;
  }
}

// Appends to `out`, in key order, the centroids of the voxels in data[0, m): points in index order whose keys
// are all equal above bit `bits`. Uses spare[0, m). Every step keeps index order within a voxel.
template <class Item>
void reduce_bucket(Item* data, Item* spare, std::size_t m, int bits, std::size_t min_points, Table& table,
                   std::vector<float>& out) {
  if (m <= kInsertionPoints) {
    for (std::size_t i = 1; i < m; ++i) {  // only larger keys move past: stable
      const Item v = data[i];
      std::size_t j = i;
      for (; j > 0 && data[j - 1].key > v.key; --j) data[j] = data[j - 1];
      data[j] = v;
    }
    append_centroids(data, m, min_points, out);
    return;
  }
  if (bits <= kDirectBits) {
    const std::uint64_t mask = (std::uint64_t{1} << bits) - 1;
    std::size_t touched = 0;
    for (std::size_t i = 0; i < m; ++i) {  // no branch per point: a new voxel is a coin flip to predict
      const auto slot = static_cast<std::uint32_t>(std::uint64_t{data[i].key} & mask);
      table.touched[touched] = slot;
      touched += table.count[slot]++ == 0;
      std::array<double, 3>& sum = table.sum[slot];
      sum[0] += data[i].xyz[0];
      sum[1] += data[i].xyz[1];
      sum[2] += data[i].xyz[2];
    }
    auto emit = [&](std::uint32_t slot) {
      const std::array<double, 3>& sum = table.sum[slot];
      append_centroid(sum[0], sum[1], sum[2], table.count[slot], min_points, out);
      table.count[slot] = 0;
      table.sum[slot] = {0.0, 0.0, 0.0};
    };
    if (touched * 16 >= mask + 1) {  // dense: walk the slots in order
      for (std::uint32_t slot = 0; slot <= mask; ++slot) {
        if (table.count[slot] != 0) emit(slot);
      }
    } else {
      std::sort(table.touched.begin(), table.touched.begin() + touched);
      for (std::size_t k = 0; k < touched; ++k) emit(table.touched[k]);
    }
    return;
  }
  const int split = std::min(kBucketBits, bits - kDirectBits);
  const int shift = bits - split;
  const std::uint64_t mask = (std::uint64_t{1} << split) - 1;
  std::array<std::uint32_t, (1u << kBucketBits) + 1> begin{};
  for (std::size_t i = 0; i < m; ++i) ++begin[1 + ((std::uint64_t{data[i].key} >> shift) & mask)];
  for (std::size_t d = 1; d <= mask + 1; ++d) begin[d] += begin[d - 1];
  std::array<std::uint32_t, 1u << kBucketBits> next;
  std::copy(begin.begin(), begin.begin() + mask + 1, next.begin());
  for (std::size_t i = 0; i < m; ++i) spare[next[(std::uint64_t{data[i].key} >> shift) & mask]++] = data[i];
  for (std::size_t d = 0; d <= mask; ++d) {
    const std::size_t size = begin[d + 1] - begin[d];
    if (size > 0) reduce_bucket(spare + begin[d], data + begin[d], size, shift, min_points, table, out);
  }
}

// What every pass of one voxel_grid() call reads: the cloud, its layout, and where each of its parts starts among
// the finite points.
struct GridInput {
  const float* p;
  std::size_t n, finite;
  const detail::VoxelLayout& layout;
  int parts;
  std::vector<std::size_t> offset;  // parts + 1 entries
};

// Where each of `parts` parts of the cloud starts among its finite points (offset[parts]: all of them).
std::vector<std::size_t> finite_offsets(const float* p, std::size_t n, std::size_t finite, int parts) {
  std::vector<std::size_t> offset(parts + 1, 0);
  if (finite != n) {
    detail::parallel_for(n, parts, [&](std::size_t b, std::size_t e, int t) {
      std::size_t c = 0;
      for (std::size_t i = b; i < e; ++i) c += detail::finite3(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
      offset[t + 1] = c;
    });
  } else {
    for (int t = 0; t < parts; ++t) offset[t + 1] = n * (t + 1) / parts - n * t / parts;
  }
  for (int t = 0; t < parts; ++t) offset[t + 1] += offset[t];
  return offset;
}

// 1. The keys of the finite points (w.keys), and per part how many of its points fall in each bucket (the
// key's bits above low_bits): count[t * buckets + d].
template <class Key>
void count_keys(const GridInput& in, Workspace<Key>& w, std::size_t buckets, int low_bits,
                std::vector<std::uint32_t>& count) {
  w.keys.resize(in.finite);
  w.items.resize(in.finite);
  count.assign(in.parts * buckets, 0);
  Keys32 layout32;
  const bool all_32_bit =
      std::is_same_v<Key, std::uint32_t> && in.finite == in.n && keys32_supported() && make_keys32(in.layout, layout32);
  const float* p = in.p;
  detail::parallel_for(in.n, in.parts, [&](std::size_t b, std::size_t e, int t) {
    std::uint32_t* c = count.data() + t * buckets;
    Key* keys = w.keys.data();
    std::size_t o = in.offset[t];
    if constexpr (std::is_same_v<Key, std::uint32_t>) {
      if (all_32_bit) {
        keys32(p + 3 * b, e - b, layout32, keys + o);
        for (std::size_t i = o; i < o + (e - b); ++i) ++c[keys[i] >> low_bits];
        return;
      }
    }
    for (std::size_t i = b; i < e; ++i) {
      const float x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
      if (!detail::finite3(x, y, z)) continue;
      const Key k = static_cast<Key>(detail::voxel_key(in.layout, x, y, z));
      keys[o++] = k;
      ++c[k >> low_bits];
    }
  });
}

// 2. Bucket d of part t starts after bucket d of the parts before it: count becomes each part's write position
// per bucket; returns where each bucket starts (buckets + 1 entries).
std::vector<std::size_t> bucket_starts(std::vector<std::uint32_t>& count, int parts, std::size_t buckets) {
  std::vector<std::size_t> bucket_begin(buckets + 1);
  std::uint32_t o = 0;
  for (std::size_t d = 0; d < buckets; ++d) {
    bucket_begin[d] = o;
    for (int t = 0; t < parts; ++t) {
      const std::uint32_t c = count[t * buckets + d];
      count[t * buckets + d] = o;
      o += c;
    }
  }
  bucket_begin[buckets] = o;
  return bucket_begin;
}

// 3. The points, with their keys, into their buckets (w.items), in index order within each.
template <class Key>
void scatter_items(const GridInput& in, Workspace<Key>& w, std::size_t buckets, int low_bits,
                   std::vector<std::uint32_t>& count) {
  using Item = KeyPoint<Key>;
  const float* p = in.p;
  detail::parallel_for(in.n, in.parts, [&](std::size_t b, std::size_t e, int t) {
    std::uint32_t* c = count.data() + t * buckets;
    const Key* keys = w.keys.data() + in.offset[t];
    Item* items = w.items.data();
    for (std::size_t i = b; i < e; ++i) {
      const float x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
      if (!detail::finite3(x, y, z)) continue;
      const Key k = *keys++;
      items[c[k >> low_bits]++] = Item{k, {x, y, z}};
    }
  });
}

// 4. Each worker takes a run of whole buckets holding about its share of the points and appends their
// centroids; buckets are in key order, so the outputs concatenate.
template <class Key>
Eigen::Matrix3Xf reduce_buckets(const GridInput& in, Workspace<Key>& w, const std::vector<std::size_t>& bucket_begin,
                                int low_bits, std::size_t min_points, int threads) {
  using Item = KeyPoint<Key>;
  const std::size_t buckets = bucket_begin.size() - 1;
  const int workers = detail::parts_for(in.finite, threads);
  std::vector<std::size_t> first_bucket(workers + 1, buckets);
  for (int t = 0; t < workers; ++t) {
    first_bucket[t] = static_cast<std::size_t>(
        std::lower_bound(bucket_begin.begin(), bucket_begin.end() - 1, in.finite * t / workers) - bucket_begin.begin());
  }
  first_bucket[0] = 0;
  if (static_cast<int>(w.scratch.size()) < workers) {
    w.scratch.resize(workers);
    w.tables.resize(workers);
    w.centroids.resize(workers);
  }
  std::vector<std::size_t> kept(workers + 1, 0);
  detail::parallel_for(workers, workers, [&](std::size_t, std::size_t, int t) {
    std::vector<float>& out = w.centroids[t];
    std::vector<Item>& scratch = w.scratch[t];
    out.clear();
    for (std::size_t d = first_bucket[t]; d < first_bucket[t + 1]; ++d) {
      const std::size_t m = bucket_begin[d + 1] - bucket_begin[d];
      if (m == 0) continue;
      if (scratch.size() < m) scratch.resize(m);
      reduce_bucket(w.items.data() + bucket_begin[d], scratch.data(), m, low_bits, min_points, w.tables[t], out);
    }
    kept[t + 1] = out.size() / 3;
  });
  for (int t = 0; t < workers; ++t) kept[t + 1] += kept[t];
  Eigen::Matrix3Xf out(3, static_cast<Eigen::Index>(kept[workers]));
  detail::parallel_for(workers, workers, [&](std::size_t, std::size_t, int t) {
    std::copy(w.centroids[t].begin(), w.centroids[t].end(), out.data() + 3 * kept[t]);
  });
  return out;
}

// A most-significant-digit pass into 2^kBucketBits buckets, then each bucket reduced to centroids while in
// cache (reduce_bucket). Every step keeps index order among equal keys. Key: 32-bit keys where they fit.
template <class Key>
Eigen::Matrix3Xf reduce_to_centroids(const GridInput& in, std::size_t min_points, int threads) {
  thread_local Workspace<Key> workspace;
  Workspace<Key>& w = workspace;  // the caller's, seen by the worker threads
  const detail::AtScopeExit release{[&] {
    if (in.n > detail::kKeepBuffersUpToPoints) w = {};
  }};
  // As many buckets as leave each one's keys to the direct table (no split pass), up to kFirstPassBits.
  const int high_bits =
      std::min(in.layout.key_bits, std::max(kBucketBits, std::min(kFirstPassBits, in.layout.key_bits - kDirectBits)));
  const int low_bits = in.layout.key_bits - high_bits;
  const std::size_t buckets = std::size_t{1} << high_bits;
  std::vector<std::uint32_t> count;
  count_keys(in, w, buckets, low_bits, count);
  const std::vector<std::size_t> bucket_begin = bucket_starts(count, in.parts, buckets);
  scatter_items(in, w, buckets, low_bits, count);
  return reduce_buckets(in, w, bucket_begin, low_bits, min_points, threads);
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
  const int parts = detail::parts_for(n, threads);
  const GridInput in{points.data(), n,     bounds.finite,
                     layout,        parts, finite_offsets(points.data(), n, bounds.finite, parts)};
  if (layout.key_bits <= 32) return reduce_to_centroids<std::uint32_t>(in, min_points, threads);
  return reduce_to_centroids<std::uint64_t>(in, min_points, threads);
}

}  // namespace stvl::filter

#include "filter/csnb.hpp"

#include <atomic>

#include "filter/detail/common.hpp"

namespace stvl::filter {

namespace {

using detail::CsnbLayout;

// Sorted cloud, cube table and per-cube neighbour spans (sorted-position ranges).
struct Grid {
  std::vector<float> x, y, z;
  std::vector<std::uint32_t> column;       // input column of each sorted point
  std::vector<std::uint32_t> cube_key;     // occupied cubes, ascending
  std::vector<std::uint32_t> cube_begin;   // first sorted point of each cube, plus the end
  std::vector<std::uint32_t> cube_of;      // cube of each sorted point
  std::vector<std::uint32_t> spans;        // per cube, rows x (begin, end)
  int rows = 0;
};

template <class Fn>
void parallel_dynamic(std::size_t n, int threads, std::size_t chunk, Fn&& fn) {
  std::atomic<std::size_t> next{0};
  detail::parallel_for(static_cast<std::size_t>(threads), threads, [&](std::size_t, std::size_t, int) {
    for (std::size_t b; (b = next.fetch_add(chunk)) < n;) fn(b, std::min(n, b + chunk));
  });
}

}  // namespace

Eigen::Matrix3Xf csnb(const Eigen::Matrix3Xf& points, const CsnbConfig& config, int threads) {
  detail::validate(config);
  detail::check_cloud_size(points.cols());
  threads = detail::resolve_threads(threads);
  const detail::Bounds bounds = detail::compute_bounds(points, threads);
  if (bounds.finite == 0) return Eigen::Matrix3Xf(3, 0);
  const CsnbLayout layout = detail::make_csnb_layout(bounds, config);
  const std::size_t n = static_cast<std::size_t>(points.cols());
  const std::size_t m = bounds.finite;
  const float* p = points.data();
  const int index_bits = std::max(1, detail::bit_width(n - 1));
  const int key_bits = 3 * layout.grid_exponent;

  std::vector<std::uint64_t> items, scratch;
  items.reserve(m);
  for (std::size_t i = 0; i < n; ++i) {
    const float x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
    if (detail::finite3(x, y, z)) items.push_back(std::uint64_t{detail::cube_key(layout, x, y, z)} << index_bits | i);
  }
  detail::radix_sort(items, scratch, index_bits, index_bits + key_bits, [](std::uint64_t v) { return v; }, threads);

  Grid g;
  g.x.resize(m);
  g.y.resize(m);
  g.z.resize(m);
  g.column.resize(m);
  g.cube_of.resize(m);
  const std::uint64_t index_mask = (std::uint64_t{1} << index_bits) - 1;
  for (std::size_t s = 0; s < m; ++s) {
    const std::uint32_t i = static_cast<std::uint32_t>(items[s] & index_mask);
    const std::uint32_t key = static_cast<std::uint32_t>(items[s] >> index_bits);
    if (s == 0 || key != g.cube_key.back()) {
      g.cube_key.push_back(key);
      g.cube_begin.push_back(static_cast<std::uint32_t>(s));
    }
    g.cube_of[s] = static_cast<std::uint32_t>(g.cube_key.size() - 1);
    g.column[s] = i;
    g.x[s] = p[3 * i];
    g.y[s] = p[3 * i + 1];
    g.z[s] = p[3 * i + 2];
  }
  const std::size_t cubes = g.cube_key.size();
  g.cube_begin.push_back(static_cast<std::uint32_t>(m));
  g.rows = detail::csnb_rows(layout);
  g.spans.assign(cubes * g.rows * 2, 0);
  std::vector<std::uint32_t> anchor(cubes);
  detail::parallel_for(cubes, detail::parts_for(cubes, threads, 1024), [&](std::size_t b, std::size_t e, int) {
    for (std::size_t c = b; c < e; ++c) {
      for (int r = 0; r < g.rows; ++r) {
        std::uint32_t lo, hi;
        if (!detail::csnb_row(layout, g.cube_key[c], r, &lo, &hi)) continue;
        const std::uint32_t c0 = detail::search_keys(g.cube_key.data(), std::uint32_t(cubes), lo, false);
        const std::uint32_t c1 = detail::search_keys(g.cube_key.data(), std::uint32_t(cubes), hi, true);
        g.spans[(c * g.rows + r) * 2] = g.cube_begin[c0];
        g.spans[(c * g.rows + r) * 2 + 1] = g.cube_begin[c1];
      }
      // Anchor: the point nearest the cube centre, ties to the earliest sorted position.
      std::uint32_t best = g.cube_begin[c];
      double best_d = detail::centre_sq_dist(layout, g.cube_key[c], g.x[best], g.y[best], g.z[best]);
      for (std::uint32_t s = best + 1; s < g.cube_begin[c + 1]; ++s) {
        const double d = detail::centre_sq_dist(layout, g.cube_key[c], g.x[s], g.y[s], g.z[s]);
        if (d < best_d) {
          best_d = d;
          best = s;
        }
      }
      anchor[c] = best;
    }
  });

  const float r2 = layout.radius_sq;
  const float* X = g.x.data();
  const float* Y = g.y.data();
  const float* Z = g.z.data();
  std::vector<std::int32_t> count(m, 0);
  std::vector<std::uint8_t> live(m, 1), is_anchor(m, 0);
  for (std::size_t c = 0; c < cubes; ++c) is_anchor[anchor[c]] = 1;

  parallel_dynamic(cubes, detail::parts_for(m, threads), 64, [&](std::size_t b, std::size_t e) {
    for (std::size_t c = b; c < e; ++c) {
      const std::uint32_t* span = &g.spans[c * g.rows * 2];
      for (std::uint32_t s = g.cube_begin[c]; s < g.cube_begin[c + 1]; ++s) {
        const float px = X[s], py = Y[s], pz = Z[s];
        std::int32_t k = 0;
        for (int r = 0; r < g.rows; ++r) {
          for (std::uint32_t j = span[2 * r]; j < span[2 * r + 1]; ++j) {
            k += (detail::sq_dist(px, py, pz, X[j], Y[j], Z[j]) < r2) & (j != s);
          }
        }
        count[s] = k;
      }
    }
  });

  // Deleting a batch: all of it leaves first, then every live point within reach loses one per deleted
  // neighbour (integer updates, so the order does not matter and CPU and CUDA agree).
  auto remove = [&](const std::vector<std::uint32_t>& batch) {
    for (std::uint32_t s : batch) live[s] = 0;
    const int parts = detail::parts_for(batch.size(), threads, 128);
    detail::parallel_for(batch.size(), parts, [&](std::size_t b, std::size_t e, int) {
      for (std::size_t q = b; q < e; ++q) {
        const std::uint32_t s = batch[q];
        const std::uint32_t* span = &g.spans[std::size_t(g.cube_of[s]) * g.rows * 2];
        for (int r = 0; r < g.rows; ++r) {
          for (std::uint32_t j = span[2 * r]; j < span[2 * r + 1]; ++j) {
            if (live[j] && detail::sq_dist(X[s], Y[s], Z[s], X[j], Y[j], Z[j]) < r2) {
              if (parts == 1) --count[j]; else __atomic_fetch_sub(&count[j], 1, __ATOMIC_RELAXED);
            }
          }
        }
      }
    });
  };

  // Batches follow one random order of the non-anchor points, fixed by the seed. A point that is not marked
  // can never be marked again (counts only fall), and deleted points never return, so the points the walk
  // has passed are settled, and the first K marked points after the cursor are a uniformly random K-subset
  // of all marked points: the same law as drawing K at random in every iteration, without a full pass each.
  std::vector<std::uint64_t> order;
  order.reserve(m - cubes);
  for (std::size_t s = 0; s < m; ++s) {
    if (!is_anchor[s]) order.push_back(detail::csnb_priority(config.seed, g.column[s], static_cast<std::uint32_t>(s)));
  }
  detail::radix_sort(order, scratch, 32, 64, [](std::uint64_t v) { return v; }, threads);
  const std::size_t K = static_cast<std::size_t>(config.batch_size);
  const std::int32_t T = config.max_neighbours;
  std::vector<std::uint32_t> batch;
  batch.reserve(K);
  for (std::size_t cursor = 0;;) {
    batch.clear();
    std::size_t next = order.size();
    for (std::size_t i = cursor; i < order.size(); ++i) {
      const std::uint32_t s = static_cast<std::uint32_t>(order[i]);
      if (!live[s] || count[s] <= T) continue;
      if (batch.size() == K) {
        next = i;
        break;
      }
      batch.push_back(s);
    }
    remove(batch);  // the last batch (K or fewer marked) deletes all still marked
    if (next == order.size()) break;
    cursor = next;
  }
  // Anchors still over the threshold take their non-anchor neighbours with them.
  for (std::size_t c = 0; c < cubes; ++c) {
    const std::uint32_t a = anchor[c];
    if (count[a] <= T) continue;
    const std::uint32_t* span = &g.spans[c * g.rows * 2];
    for (int r = 0; r < g.rows; ++r) {
      for (std::uint32_t j = span[2 * r]; j < span[2 * r + 1]; ++j) {
        if (!is_anchor[j] && detail::sq_dist(X[a], Y[a], Z[a], X[j], Y[j], Z[j]) < r2) live[j] = 0;
      }
    }
  }

  std::size_t kept = 0;
  for (std::size_t s = 0; s < m; ++s) kept += live[s];
  Eigen::Matrix3Xf out(3, static_cast<Eigen::Index>(kept));
  for (std::size_t s = 0, o = 0; s < m; ++s) {
    if (!live[s]) continue;
    out.col(static_cast<Eigen::Index>(o++)) << X[s], Y[s], Z[s];
  }
  return out;
}

}  // namespace stvl::filter

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
  std::vector<std::uint32_t> spans;        // per cube, rows x (first cube, end cube)
  int rows = 0;
};

template <class Fn>
void parallel_dynamic(std::size_t n, int threads, std::size_t chunk, Fn&& fn) {
  std::atomic<std::size_t> next{0};
  detail::parallel_for(static_cast<std::size_t>(threads), threads, [&](std::size_t, std::size_t, int) {
    for (std::size_t b; (b = next.fetch_add(chunk)) < n;) fn(b, std::min(n, b + chunk));
  });
}

// Marked = a live point with more than `threshold` live neighbours. Counted lazily with early exit: the
// centre row (the point's own cube and its x-neighbours) first, then the others.
struct Evaluator {
  const float* X;  // sorted points
  const float* Y;
  const float* Z;
  const std::uint8_t* live;
  const std::uint32_t* spans;
  const std::uint32_t* cube_of;
  int rows;
  int centre_row;
  float r2;
  int threshold;
  // The candidates: the points not yet known dead, per cube from start[c], with their sorted positions.
  const float* CX;
  const float* CY;
  const float* CZ;
  const std::uint32_t* id;
  const std::uint32_t* start;

  bool marked(std::uint32_t s) const {
    const std::uint32_t* span = spans + std::size_t(cube_of[s]) * rows * 2;
    const float px = X[s], py = Y[s], pz = Z[s];
    int k = 0;
    for (int q = -1; q < rows; ++q) {
      const int r = q < 0 ? centre_row : q;
      if (q == centre_row) continue;
      const std::uint32_t b = start[span[2 * r]], e = start[span[2 * r + 1]];
      for (std::uint32_t j = b; j < e; ++j) {
        const std::uint32_t o = id[j];
        k += (detail::sq_dist(px, py, pz, CX[j], CY[j], CZ[j]) < r2) & live[o] & (o != s);
      }
      if (k > threshold) return true;
    }
    return false;
  }
};

// Candidate arrays without the dead points, rebuilt when enough have died.
struct Compact {
  std::vector<float> x, y, z;
  std::vector<std::uint32_t> id, start;
  void rebuild(const Grid& g, const std::vector<std::uint8_t>& live, std::size_t cubes) {
    const std::size_t m = g.x.size();
    x.resize(m);
    y.resize(m);
    z.resize(m);
    id.resize(m);
    start.resize(cubes + 1);
    std::uint32_t o = 0;
    for (std::size_t c = 0; c < cubes; ++c) {
      start[c] = o;
      for (std::uint32_t s = g.cube_begin[c]; s < g.cube_begin[c + 1]; ++s) {
        x[o] = g.x[s];
        y[o] = g.y[s];
        z[o] = g.z[s];
        id[o] = s;
        o += live[s];
      }
    }
    start[cubes] = o;
  }
};

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

  // Group points by cube in index order: runs of consecutive points in one cube become one entry
  // (key << index_bits | first index), run_end[first] ends the run; a stable sort on the key bits.
  std::vector<std::uint64_t> items(n), scratch(n);
  std::vector<std::uint32_t> run_end(n);
  const int parts = detail::parts_for(n, threads, 16384);
  std::vector<detail::Segment<std::uint64_t>> segments(parts);
  detail::parallel_for(n, parts, [&](std::size_t b, std::size_t e, int t) {
    std::uint64_t* out = items.data() + b;
    std::size_t count = 0;
    std::uint32_t current = 0, run_begin = 0;
    bool in_run = false;
    for (std::size_t i = b; i < e; ++i) {
      const float x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
      if (!detail::finite3(x, y, z)) {
        if (in_run) run_end[run_begin] = static_cast<std::uint32_t>(i);
        in_run = false;
        continue;
      }
      const std::uint32_t key = detail::cube_key(layout, x, y, z);
      if (in_run && key == current) continue;
      if (in_run) run_end[run_begin] = static_cast<std::uint32_t>(i);
      out[count++] = std::uint64_t{key} << index_bits | i;
      current = key;
      run_begin = static_cast<std::uint32_t>(i);
      in_run = true;
    }
    if (in_run) run_end[run_begin] = static_cast<std::uint32_t>(e);
    segments[t] = {out, count};
  });
  std::size_t runs = 0;
  for (const auto& seg : segments) runs += seg.size;
  const std::uint64_t* sorted = detail::radix_sort_segments(
      segments, items.data(), scratch.data(), index_bits, index_bits + key_bits, [](std::uint64_t v) { return v; },
      threads);

  Grid g;
  g.x.resize(m);
  g.y.resize(m);
  g.z.resize(m);
  g.column.resize(m);
  g.cube_of.resize(m);
  const std::uint64_t index_mask = (std::uint64_t{1} << index_bits) - 1;
  {
    std::size_t s = 0;
    for (std::size_t r = 0; r < runs; ++r) {
      const std::uint32_t first = static_cast<std::uint32_t>(sorted[r] & index_mask);
      const std::uint32_t key = static_cast<std::uint32_t>(sorted[r] >> index_bits);
      if (g.cube_key.empty() || key != g.cube_key.back()) {
        g.cube_key.push_back(key);
        g.cube_begin.push_back(static_cast<std::uint32_t>(s));
      }
      const std::uint32_t c = static_cast<std::uint32_t>(g.cube_key.size() - 1);
      for (std::uint32_t i = first; i < run_end[first]; ++i, ++s) {
        g.cube_of[s] = c;
        g.column[s] = i;
        g.x[s] = p[3 * std::size_t(i)];
        g.y[s] = p[3 * std::size_t(i) + 1];
        g.z[s] = p[3 * std::size_t(i) + 2];
      }
    }
  }
  const std::size_t cubes = g.cube_key.size();
  g.cube_begin.push_back(static_cast<std::uint32_t>(m));
  g.rows = detail::csnb_rows(layout);
  g.spans.assign(cubes * g.rows * 2, 0);
  std::vector<std::uint32_t> anchor(cubes);
  const int cube_parts = detail::parts_for(cubes, threads, 1024);
  detail::parallel_for(cubes, cube_parts, [&](std::size_t b, std::size_t e, int) {
    // Per row the searched key ranges grow with the cube, so two pointers per row walk the cube table.
    std::vector<std::uint32_t> lo_at(g.rows, 0), hi_at(g.rows, 0);
    bool started = false;
    const std::uint32_t* keys = g.cube_key.data();
    for (std::size_t c = b; c < e; ++c) {
      for (int r = 0; r < g.rows; ++r) {
        std::uint32_t lo, hi;
        if (!detail::csnb_row(layout, keys[c], r, &lo, &hi)) continue;
        std::uint32_t& c0 = lo_at[r];
        std::uint32_t& c1 = hi_at[r];
        if (!started || c0 == 0) {
          c0 = detail::search_keys(keys, std::uint32_t(cubes), lo, false);
          c1 = detail::search_keys(keys, std::uint32_t(cubes), hi, true);
        } else {
          while (c0 < cubes && keys[c0] < lo) ++c0;
          if (c1 < c0) c1 = c0;
          while (c1 < cubes && keys[c1] <= hi) ++c1;
        }
        g.spans[(c * g.rows + r) * 2] = c0;
        g.spans[(c * g.rows + r) * 2 + 1] = c1;
      }
      started = true;
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

  std::vector<std::uint8_t> live(m, 1), settled(m, 0), is_anchor(m, 0);
  for (std::size_t c = 0; c < cubes; ++c) is_anchor[anchor[c]] = 1;
  const int side = 2 * layout.reach + 1;
  Compact compact;
  compact.rebuild(g, live, cubes);
  Evaluator eval{g.x.data(),
                 g.y.data(),
                 g.z.data(),
                 live.data(),
                 g.spans.data(),
                 g.cube_of.data(),
                 g.rows,
                 layout.reach + layout.reach * side,
                 layout.radius_sq,
                 config.max_neighbours,
                 compact.x.data(),
                 compact.y.data(),
                 compact.z.data(),
                 compact.id.data(),
                 compact.start.data()};
  std::size_t alive = m, dead_since = 0;

  // Batches follow one random order of the non-anchor points, fixed by the seed. A point that is not marked
  // can never be marked again (counts only fall), and deleted points never return, so the points the walk
  // has passed are settled, and the first K marked points after the cursor are a uniformly random K-subset
  // of all marked points: the same law as drawing K at random in every iteration, without a full pass each.
  // A point's mark is counted when the walk reaches it, on the live set of that moment (the batch being
  // gathered is deleted only once complete), which is exactly what per-point neighbour counts kept up to
  // date by decrements would say; a point found unmarked stays settled.
  std::vector<std::uint64_t> order;
  order.reserve(m - cubes);
  for (std::size_t s = 0; s < m; ++s) {
    if (!is_anchor[s]) order.push_back(detail::csnb_priority(config.seed, g.column[s], static_cast<std::uint32_t>(s)));
  }
  detail::radix_sort(order, scratch, 32, 64, [](std::uint64_t v) { return v; }, threads);
  const std::size_t K = static_cast<std::size_t>(config.batch_size);
  const float* X = g.x.data();
  const float* Y = g.y.data();
  const float* Z = g.z.data();
  std::vector<std::uint32_t> batch;
  batch.reserve(std::min(K, m));
  for (std::size_t cursor = 0;;) {
    batch.clear();
    std::size_t next = order.size();
    for (std::size_t i = cursor; i < order.size(); ++i) {
      // The walk visits points at random: prefetch the flags and cube of a point 16 ahead, its neighbour
      // spans and centre row 8 ahead.
      if (i + 16 < order.size()) {
        const std::uint32_t f = static_cast<std::uint32_t>(order[i + 16]);
        __builtin_prefetch(&live[f]);
        __builtin_prefetch(&settled[f]);
        __builtin_prefetch(&g.cube_of[f]);
      }
      if (i + 8 < order.size()) {
        const std::uint32_t f = static_cast<std::uint32_t>(order[i + 8]);
        const std::uint32_t* span = &g.spans[std::size_t(g.cube_of[f]) * g.rows * 2];
        __builtin_prefetch(span);
        __builtin_prefetch(&compact.start[span[2 * eval.centre_row]]);
        __builtin_prefetch(&X[f]);
        __builtin_prefetch(&Y[f]);
        __builtin_prefetch(&Z[f]);
      }
      const std::uint32_t s = static_cast<std::uint32_t>(order[i]);
      if (!live[s] || settled[s]) continue;
      if (!eval.marked(s)) {
        settled[s] = 1;
        continue;
      }
      if (batch.size() == K) {
        next = i;
        break;
      }
      batch.push_back(s);
    }
    for (std::uint32_t s : batch) live[s] = 0;  // the last batch (K or fewer marked) deletes all still marked
    alive -= batch.size();
    dead_since += batch.size();
    if (dead_since * 2 > alive && next != order.size()) {
      compact.rebuild(g, live, cubes);
      dead_since = 0;
    }
    if (next == order.size()) break;
    cursor = next;
  }
  // Anchors still over the threshold (on the final live set) take their non-anchor neighbours with them.
  std::vector<std::uint8_t> claims(cubes, 0);
  detail::parallel_for(cubes, cube_parts, [&](std::size_t b, std::size_t e, int) {
    for (std::size_t c = b; c < e; ++c) claims[c] = eval.marked(anchor[c]);
  });
  const float r2 = layout.radius_sq;
  for (std::size_t c = 0; c < cubes; ++c) {
    if (!claims[c]) continue;
    const std::uint32_t a = anchor[c];
    const std::uint32_t* span = &g.spans[c * g.rows * 2];
    for (int r = 0; r < g.rows; ++r) {
      for (std::uint32_t j = g.cube_begin[span[2 * r]]; j < g.cube_begin[span[2 * r + 1]]; ++j) {
        if (!is_anchor[j] && detail::sq_dist(X[a], Y[a], Z[a], X[j], Y[j], Z[j]) < r2) live[j] = 0;
      }
    }
  }

  std::size_t kept = 0;
  for (std::size_t s = 0; s < m; ++s) kept += live[s];
  Eigen::Matrix3Xf out(3, static_cast<Eigen::Index>(kept));
  float* o = out.data();
  for (std::size_t s = 0; s < m; ++s) {
    if (!live[s]) continue;
    o[0] = X[s];
    o[1] = Y[s];
    o[2] = Z[s];
    o += 3;
  }
  return out;
}

}  // namespace stvl::filter

#include "filter/csnb.hpp"

#include <algorithm>
#include <limits>

#include "filter/detail/common.hpp"
#include "filter/detail/csnb_walk.hpp"

namespace stvl::filter {

namespace {

using detail::CsnbLayout;
using namespace detail::csnb;

// Two-pass parallel fill: count(b, e) says how many outputs the part [b, e) makes, prepare(total) makes room,
// write(b, e, first) writes them from `first`; returns the total. Parts are contiguous ranges of [0, n), so
// the outputs keep the input order.
template <class Count, class Prepare, class Write>
std::size_t parallel_compact(std::size_t n, int threads, std::size_t grain, Count&& count, Prepare&& prepare,
                             Write&& write) {
  const int parts = detail::parts_for(n, threads, grain);
  std::vector<std::size_t> offset(parts + 1, 0);
  detail::parallel_for(n, parts, [&](std::size_t b, std::size_t e, int t) { offset[t + 1] = count(b, e); });
  for (int t = 0; t < parts; ++t) offset[t + 1] += offset[t];
  prepare(offset[parts]);
  detail::parallel_for(n, parts, [&](std::size_t b, std::size_t e, int t) { write(b, e, offset[t]); });
  return offset[parts];
}

// spans[(c * rows + r) * 2 + {0, 1}]: the occupied cubes [first, end) in row r (detail::csnb_row) of cube c,
// for the cubes c in [b, e) of the sorted `keys` (keys[cubes] = UINT32_MAX). A row's key range moves up with
// the cube's key, so per row one pair of pointers walks the table (after a binary search at b).
void find_spans(const CsnbLayout& l, const std::uint32_t* keys, std::size_t cubes, std::size_t b, std::size_t e,
                std::uint32_t* spans) {
  const int rows = detail::csnb_rows(l), side = 2 * l.reach + 1, bits = l.grid_exponent, top = (1 << bits) - 1;
  const std::uint32_t count = static_cast<std::uint32_t>(cubes);
  // detail::csnb_row with each row's offsets worked out once (it divides by `side` per call); per row, the
  // pointer pair and whether it was placed yet.
  std::vector<int> dy(rows), dz(rows);
  std::vector<std::uint32_t> first(rows, 0), end(rows, 0);
  std::vector<char> placed(rows, 0);
  for (int r = 0; r < rows; ++r) {
    dy[r] = r % side - l.reach;
    dz[r] = r / side - l.reach;
  }
  for (std::size_t c = b; c < e; ++c) {
    const int key = int(keys[c]), x = key & top, y = (key >> bits) & top, z = (key >> (2 * bits)) & top;
    const std::uint32_t x0 = std::uint32_t(std::max(x - l.reach, 0)), x1 = std::uint32_t(std::min(x + l.reach, top));
    std::uint32_t* span = spans + c * rows * 2;
    // The next cube of the same row as the last: every row's bounds rise by at most 1 and keys are distinct,
    // so each pointer moves by at most one cube.
    const bool next_in_row = c > b && x != 0 && keys[c - 1] == std::uint32_t(key - 1);
    for (int r = 0; r < rows; ++r) {
      const int ry = y + dy[r], rz = z + dz[r];
      if (ry < 0 || ry > top || rz < 0 || rz > top) {
        span[2 * r] = span[2 * r + 1] = 0;
        continue;
      }
      const std::uint32_t base = std::uint32_t(ry << bits) | std::uint32_t(rz << (2 * bits));
      const std::uint32_t lo = base | x0, hi = base | x1;
      std::uint32_t c0 = first[r], c1 = end[r];
      if (next_in_row) {
        c0 += keys[c0] < lo;
        c1 = std::max(c1, c0);
        c1 += keys[c1] <= hi;
        first[r] = span[2 * r] = c0;
        end[r] = span[2 * r + 1] = c1;
        continue;
      }
      if (!placed[r]) {
        c0 = detail::search_keys(keys, count, lo, false);
        c1 = detail::search_keys(keys, count, hi, true);
        placed[r] = 1;
      }
      // keys[count] is a sentinel above every key. The pointers mostly move by 0 to 3: steps without branches
      // first (a loop's exit would mispredict on almost every cube), a loop for the rest.
      c0 += keys[c0] < lo;
      c0 += keys[c0] < lo;
      while (keys[c0] < lo) ++c0;
      c1 = std::max(c1, c0);
      c1 += keys[c1] <= hi;
      c1 += keys[c1] <= hi;
      c1 += keys[c1] <= hi;
      while (keys[c1] <= hi) ++c1;
      first[r] = span[2 * r] = c0;
      end[r] = span[2 * r + 1] = c1;
    }
  }
}

// The finite points of p[0 .. 3n) (m of them) as (cube key << 32 | index), in index order, then stably sorted by
// key; returns the sorted items (in w.items or w.scratch).
const std::uint64_t* sort_by_cube(Workspace& w, const float* p, std::size_t n, std::size_t m, const CsnbLayout& layout,
                                  bool avx2, int threads) {
  const int key_bits = 3 * layout.grid_exponent;
  w.items.resize(n);
  w.scratch.resize(n);
  const int parts = detail::parts_for(n, threads, 16384);
  std::vector<detail::Segment<std::uint64_t>> segments(parts);
  const bool all_finite = m == n;
  detail::parallel_for(n, parts, [&](std::size_t b, std::size_t e, int t) {
    std::uint64_t* out = w.items.data() + b;
    std::size_t count = 0;
    if (all_finite) {
      cube_keys(avx2, p + 3 * b, e - b, layout, out);
      for (std::size_t i = b; i < e; ++i) out[i - b] = out[i - b] << 32 | i;
      count = e - b;
    } else {
      for (std::size_t i = b; i < e; ++i) {
        const float x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
        if (detail::finite3(x, y, z)) out[count++] = std::uint64_t{detail::cube_key(layout, x, y, z)} << 32 | i;
      }
    }
    segments[t] = {out, count};
  });
  return detail::radix_sort_segments(
      segments, w.items.data(), w.scratch.data(), 32, 32 + key_bits, [](std::uint64_t v) { return v; }, threads);
}

// The sorted points (w.points, w.column) and the cube table (w.cube_key with a sentinel, w.cube_begin): a cube
// starts wherever the key changes. Returns the number of cubes.
std::size_t build_cube_table(Workspace& w, const float* p, const std::uint64_t* sorted, std::size_t m, int threads) {
  auto key_at = [&](std::size_t s) { return static_cast<std::uint32_t>(sorted[s] >> 32); };
  auto opens_cube = [&](std::size_t s) { return s == 0 || key_at(s) != key_at(s - 1); };
  const int point_parts = detail::parts_for(m, threads, 16384);
  std::vector<std::size_t> cube_offset(point_parts + 1, 0);
  detail::parallel_for(m, point_parts, [&](std::size_t b, std::size_t e, int t) {
    std::size_t opened = 0;
    for (std::size_t s = b; s < e; ++s) opened += opens_cube(s);
    cube_offset[t + 1] = opened;
  });
  for (int t = 0; t < point_parts; ++t) cube_offset[t + 1] += cube_offset[t];
  const std::size_t cubes = cube_offset[point_parts];
  w.points.resize(m);
  w.column.resize(m);
  w.cube_key.resize(cubes + 1);
  w.cube_key[cubes] = std::numeric_limits<std::uint32_t>::max();  // a sentinel for find_spans
  w.cube_begin.resize(cubes + 1);
  detail::parallel_for(m, point_parts, [&](std::size_t b, std::size_t e, int t) {
    std::size_t c = cube_offset[t];
    for (std::size_t s = b; s < e; ++s) {
      if (opens_cube(s)) {
        w.cube_key[c] = key_at(s);
        w.cube_begin[c++] = static_cast<std::uint32_t>(s);
      }
      if (s + 16 < e) __builtin_prefetch(p + 3 * static_cast<std::uint32_t>(sorted[s + 16]));  // a gather
      const std::size_t i = static_cast<std::uint32_t>(sorted[s]);
      w.points[s] = {p[3 * i], p[3 * i + 1], p[3 * i + 2], static_cast<std::uint32_t>(c - 1)};
      w.column[s] = static_cast<std::uint32_t>(i);
    }
  });
  w.cube_begin[cubes] = static_cast<std::uint32_t>(m);
  return cubes;
}

// Per cube and row (detail::csnb_row), the range of occupied cubes the row covers (w.spans); the anchor
// (w.anchor, w.is_anchor): the point nearest the cube centre, ties to the earliest sorted position.
void find_spans_and_anchors(Workspace& w, const CsnbLayout& layout, std::size_t cubes, std::size_t m, int threads) {
  const int rows = detail::csnb_rows(layout);
  w.spans.resize(cubes * rows * 2);
  w.anchor.resize(cubes);
  w.is_anchor.assign(m, 0);
  const int cube_parts = detail::parts_for(cubes, threads, 1024);
  detail::parallel_for(cubes, cube_parts, [&](std::size_t b, std::size_t e, int) {
    find_spans(layout, w.cube_key.data(), cubes, b, e, w.spans.data());
    const Point* q = w.points.data();
    for (std::size_t c = b; c < e; ++c) {
      std::uint32_t best = w.cube_begin[c];
      double best_d = detail::centre_sq_dist(layout, w.cube_key[c], q[best].x, q[best].y, q[best].z);
      for (std::uint32_t s = best + 1; s < w.cube_begin[c + 1]; ++s) {
        const double d = detail::centre_sq_dist(layout, w.cube_key[c], q[s].x, q[s].y, q[s].z);
        if (d < best_d) {
          best_d = d;
          best = s;
        }
      }
      w.anchor[c] = best;
      w.is_anchor[best] = 1;
    }
  });
}

// The walk's order (w.order): the non-anchor points by their seeded priority. Returns their number.
std::size_t random_order(Workspace& w, std::size_t m, std::uint64_t seed, int threads) {
  const std::size_t order_size = parallel_compact(
      m, threads, 16384,
      [&](std::size_t b, std::size_t e) {
        std::size_t count = 0;
        for (std::size_t s = b; s < e; ++s) count += !w.is_anchor[s];
        return count;
      },
      [](std::size_t) {},
      [&](std::size_t b, std::size_t e, std::size_t first) {
        for (std::size_t s = b; s < e; ++s) {
          if (w.is_anchor[s]) continue;
          w.items[first++] = detail::csnb_priority(seed, w.column[s], static_cast<std::uint32_t>(s));
        }
      });
  w.order.assign(w.items.begin(), w.items.begin() + order_size);
  detail::radix_sort(
      w.order, w.scratch, 32, 64, [](std::uint64_t v) { return v; }, threads);
  return order_size;
}

// Sparse points are settled from the start; the rest that are not sure go to the walk (w.unsure by walk id,
// w.unsure_points their points).
void settle_sparse_and_list_unsure(Workspace& w, std::size_t m, std::size_t order_size, std::uint32_t never) {
  w.settled_bits.assign((m + 63) / 64, 0);
  for_each_bit(w.sparse, [&](std::uint32_t j) { settle(w, j, never); });
  w.unsure.clear();
  for (std::size_t k = 0; k < w.sure.size(); ++k) {
    for (std::uint64_t word = ~(w.sure[k] | w.sparse[k]); word != 0; word &= word - 1) {
      const std::size_t j = k * 64 + std::size_t(__builtin_ctzll(word));
      if (j >= order_size) break;  // the last word's unused bits
      w.unsure.push_back(static_cast<std::uint32_t>(j));
    }
  }
  w.unsure_points.resize(w.unsure.size());
  for (std::size_t k = 0; k < w.unsure.size(); ++k) w.unsure_points[k] = w.points[std::uint32_t(w.order[w.unsure[k]])];
}

// The kept points in sorted order: the anchors, and the settled points no claim deleted.
Eigen::Matrix3Xf kept_points(Workspace& w, std::size_t m, int threads) {
  const Point* q = w.points.data();
  w.result.resize(m);
  Eigen::Matrix3Xf out;
  parallel_compact(
      m, threads, 16384,
      [&](std::size_t b, std::size_t e) {
        std::size_t kept = 0;
        for (std::size_t s = b; s < e; ++s) {
          w.result[s] = w.is_anchor[s] || (bit(w.settled_bits.data(), std::uint32_t(s)) && !w.claimed[s]);
          kept += w.result[s];
        }
        return kept;
      },
      [&](std::size_t kept) { out.resize(3, static_cast<Eigen::Index>(kept)); },
      [&](std::size_t b, std::size_t e, std::size_t first) {
        float* o = out.data() + 3 * first;
        for (std::size_t s = b; s < e; ++s) {
          if (!w.result[s]) continue;
          o[0] = q[s].x;
          o[1] = q[s].y;
          o[2] = q[s].z;
          o += 3;
        }
      });
  return out;
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
  thread_local Workspace workspace;
  Workspace& w = workspace;  // named through a reference: the worker threads must see the caller's buffers
  const detail::AtScopeExit release{[&] {
    if (n > detail::kKeepBuffersUpToPoints) w = Workspace{};
  }};
  const bool avx2 = avx2_supported() && m < (std::size_t{1} << 31);  // ids compared as signed 32-bit

  const std::uint64_t* sorted = sort_by_cube(w, p, n, m, layout, avx2, threads);
  const std::size_t cubes = build_cube_table(w, p, sorted, m, threads);
  find_spans_and_anchors(w, layout, cubes, m, threads);

  // Batches follow one random order of the non-anchor points, fixed by the seed. A point that is not marked
  // can never be marked again (counts only fall), and deleted points never return, so the points the walk
  // has passed are settled, and the first K marked points after the cursor are a uniformly random K-subset
  // of all marked points: the same law as drawing K at random in every iteration, without a full pass each.
  // A point's mark is counted when the walk reaches it, on the live set of that moment (the batch being
  // gathered is deleted only once complete), which is exactly what per-point neighbour counts kept up to
  // date by decrements would say; a point found unmarked stays settled.
  const std::size_t order_size = random_order(w, m, config.seed, threads);
  const std::uint32_t never = avx2 ? kNeverAvx2 : kNeverPlain;
  init_candidates(w, order_size, never, threads);
  const int side = 2 * layout.reach + 1;
  Counter counter{w.candidates.data(),
                  w.cube_begin.data(),
                  w.spans.data(),
                  detail::csnb_rows(layout),
                  layout.reach + layout.reach * side,
                  layout.radius_sq,
                  config.max_neighbours};
  find_sure(w, counter, cubes, std::uint32_t(order_size), avx2, threads);
  settle_sparse_and_list_unsure(w, m, order_size, never);
  walk(w, counter, order_size, static_cast<std::size_t>(config.batch_size), never, avx2, threads);
  claim(w, counter, cubes, avx2, threads);
  return kept_points(w, m, threads);
}

}  // namespace stvl::filter

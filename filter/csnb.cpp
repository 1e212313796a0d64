#include "filter/csnb.hpp"

#include <algorithm>
#include <limits>

#include "filter/detail/common.hpp"

namespace stvl::filter {

namespace {

using detail::CsnbLayout;

// A point (cube = index into the occupied-cube table) and a candidate neighbour: the points that were live
// at the last compaction, per cube in sorted order, with x set to NaN once deleted (NaN is never < r2).
// The walk visits points in a random order, so everything it reads per point is stored by walk id (the
// position in that order; anchors follow, by cube) and read sequentially; only neighbours are random.
struct Point {
  float x, y, z;
  std::uint32_t cube;
};
struct Candidate {
  float x, y, z;
  std::uint32_t id;  // walk id
};

enum : std::uint8_t { kLive = 0, kSettled = 1, kDead = 2 };  // a settled point is live and can never be marked
enum : std::uint8_t { kSkip = 0, kUnmarked = 1, kMarked = 2 };  // what the walk found for a point

// Buffers kept per calling thread (see voxel_grid.cpp): fresh ones would page-fault on every frame.
struct Workspace {
  std::vector<std::uint64_t> items, scratch, order;
  std::vector<std::uint32_t> run_end, column, cube_key, cube_begin, spans, anchor, slot_of, start, row_slots, batch,
      walk_of;
  std::vector<Point> points, walk_points;
  std::vector<Candidate> candidates, next_candidates;
  std::vector<std::uint32_t> next_start;
  std::vector<std::uint8_t> state, is_anchor, result, claims;
};

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

// Marked = a live point with more than `threshold` live neighbours. Counted with early exit every 16
// candidates, the centre row (the point's own cube and its x-neighbours) first.
struct Evaluator {
  const Point* points;
  const Candidate* candidates;
  const std::uint32_t* start;      // per cube: its first candidate
  const std::uint32_t* row_slots;  // per cube and row: the candidate range [first, end)
  int rows;
  int centre_row;
  float r2;
  int threshold;

  bool marked(std::uint32_t id) const {
    const Point p = points[id];
    const std::uint32_t* slots = row_slots + std::size_t(p.cube) * rows * 2;
    int k = 0;
    auto count = [&](std::uint32_t j, std::uint32_t e) {
      while (j < e) {
        for (const std::uint32_t stop = std::min(e, j + 16); j < stop; ++j) {
          const Candidate& c = candidates[j];
          k += (detail::sq_dist(p.x, p.y, p.z, c.x, c.y, c.z) < r2) & (c.id != id);
        }
        if (k > threshold) return true;
      }
      return false;
    };
    // The point's own cube, the rest of its row, then the other rows.
    const std::uint32_t own_begin = start[p.cube], own_end = start[p.cube + 1];
    if (count(own_begin, own_end) || count(slots[2 * centre_row], own_begin) ||
        count(own_end, slots[2 * centre_row + 1]))
      return true;
    for (int r = 0; r < rows; ++r) {
      if (r != centre_row && count(slots[2 * r], slots[2 * r + 1])) return true;
    }
    return false;
  }
  void prefetch_rows(std::uint32_t id) const {
    const std::uint32_t* slots = row_slots + std::size_t(points[id].cube) * rows * 2;
    __builtin_prefetch(slots);
    __builtin_prefetch(slots + 16);
  }
  void prefetch_centre(std::uint32_t id) const {
    const std::uint32_t* slots = row_slots + std::size_t(points[id].cube) * rows * 2;
    __builtin_prefetch(&start[points[id].cube]);
    __builtin_prefetch(&candidates[slots[2 * centre_row]]);
  }
};

void update_row_slots(Workspace& w, std::size_t cubes, int rows, int threads) {
  w.row_slots.resize(cubes * rows * 2);
  detail::parallel_for(cubes * rows * 2, detail::parts_for(cubes * rows * 2, threads, 16384),
                       [&](std::size_t b, std::size_t e, int) {
                         for (std::size_t i = b; i < e; ++i) w.row_slots[i] = w.start[w.spans[i]];
                       });
}

// The first candidates: every point (all are live), per cube in sorted order, and each row's candidate range.
void init_candidates(Workspace& w, std::size_t cubes, int rows, int threads) {
  const std::size_t m = w.points.size();
  w.candidates.resize(m);
  w.start.assign(w.cube_begin.begin(), w.cube_begin.begin() + cubes + 1);
  detail::parallel_for(m, detail::parts_for(m, threads, 16384), [&](std::size_t b, std::size_t e, int) {
    for (std::size_t s = b; s < e; ++s) {
      const std::uint32_t id = w.walk_of[s];
      w.candidates[s] = {w.points[s].x, w.points[s].y, w.points[s].z, id};
      w.slot_of[id] = static_cast<std::uint32_t>(s);
    }
  });
  update_row_slots(w, cubes, rows, threads);
}

// Without the deleted candidates (x = NaN), read from the candidates themselves: only what is left.
void recompact(Workspace& w, std::size_t cubes, int rows, int threads) {
  w.next_candidates.resize(w.candidates.size());
  w.next_start.resize(cubes + 1);
  const std::uint32_t* start = w.start.data();
  const Candidate* from = w.candidates.data();
  const std::size_t total = parallel_compact(
      cubes, threads, 2048,
      [&](std::size_t b, std::size_t e) {
        std::size_t live = 0;
        for (std::uint32_t j = start[b]; j < start[e]; ++j) live += from[j].x == from[j].x;
        return live;
      },
      [](std::size_t) {},
      [&](std::size_t b, std::size_t e, std::size_t first) {
        std::uint32_t o = static_cast<std::uint32_t>(first);
        for (std::size_t c = b; c < e; ++c) {
          w.next_start[c] = o;
          for (std::uint32_t j = start[c]; j < start[c + 1]; ++j) {
            if (from[j].x != from[j].x) continue;
            w.next_candidates[o] = from[j];
            w.slot_of[from[j].id] = o++;
          }
        }
      });
  w.next_start[cubes] = static_cast<std::uint32_t>(total);
  w.candidates.swap(w.next_candidates);
  w.start.swap(w.next_start);
  update_row_slots(w, cubes, rows, threads);
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
  thread_local Workspace workspace;
  Workspace& w = workspace;  // named through a reference: the pool's workers must see the caller's buffers
  const detail::AtScopeExit release{[&] {
    if (n > detail::kKeepBuffersUpToPoints) w = Workspace{};
  }};

  // Group points by cube in index order: runs of consecutive points in one cube become one entry
  // (key << index_bits | first index), run_end[first] ends the run; a stable sort on the key bits.
  w.items.resize(n);
  w.scratch.resize(n);
  w.run_end.resize(n);
  const int parts = detail::parts_for(n, threads, 16384);
  std::vector<detail::Segment<std::uint64_t>> segments(parts);
  detail::parallel_for(n, parts, [&](std::size_t b, std::size_t e, int t) {
    std::uint64_t* out = w.items.data() + b;
    std::size_t count = 0;
    std::uint32_t current = 0, run_begin = 0;
    bool in_run = false;
    for (std::size_t i = b; i < e; ++i) {
      const float x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
      if (!detail::finite3(x, y, z)) {
        if (in_run) w.run_end[run_begin] = static_cast<std::uint32_t>(i);
        in_run = false;
        continue;
      }
      const std::uint32_t key = detail::cube_key(layout, x, y, z);
      if (in_run && key == current) continue;
      if (in_run) w.run_end[run_begin] = static_cast<std::uint32_t>(i);
      out[count++] = std::uint64_t{key} << index_bits | i;
      current = key;
      run_begin = static_cast<std::uint32_t>(i);
      in_run = true;
    }
    if (in_run) w.run_end[run_begin] = static_cast<std::uint32_t>(e);
    segments[t] = {out, count};
  });
  std::size_t runs = 0;
  for (const auto& seg : segments) runs += seg.size;
  const std::uint64_t* sorted = detail::radix_sort_segments(
      segments, w.items.data(), w.scratch.data(), index_bits, index_bits + key_bits, [](std::uint64_t v) { return v; },
      threads);

  // Sorted points, and the cube table: a cube starts at every run whose key differs from the previous run's.
  const std::uint64_t index_mask = (std::uint64_t{1} << index_bits) - 1;
  auto run_key = [&](std::size_t r) { return static_cast<std::uint32_t>(sorted[r] >> index_bits); };
  auto run_first = [&](std::size_t r) { return static_cast<std::uint32_t>(sorted[r] & index_mask); };
  auto opens_cube = [&](std::size_t r) { return r == 0 || run_key(r) != run_key(r - 1); };
  const int run_parts = detail::parts_for(runs, threads, 4096);
  std::vector<std::size_t> point_offset(run_parts + 1, 0), cube_offset(run_parts + 1, 0);
  detail::parallel_for(runs, run_parts, [&](std::size_t b, std::size_t e, int t) {
    std::size_t count = 0, opened = 0;
    for (std::size_t r = b; r < e; ++r) {
      count += w.run_end[run_first(r)] - run_first(r);
      opened += opens_cube(r);
    }
    point_offset[t + 1] = count;
    cube_offset[t + 1] = opened;
  });
  for (int t = 0; t < run_parts; ++t) {
    point_offset[t + 1] += point_offset[t];
    cube_offset[t + 1] += cube_offset[t];
  }
  const std::size_t cubes = cube_offset[run_parts];
  w.points.resize(m);
  w.column.resize(m);
  w.cube_key.resize(cubes);
  w.cube_begin.resize(cubes + 1);
  detail::parallel_for(runs, run_parts, [&](std::size_t b, std::size_t e, int t) {
    std::size_t s = point_offset[t], c = cube_offset[t];
    for (std::size_t r = b; r < e; ++r) {
      if (opens_cube(r)) {
        w.cube_key[c] = run_key(r);
        w.cube_begin[c++] = static_cast<std::uint32_t>(s);
      }
      const std::uint32_t cube = static_cast<std::uint32_t>(c - 1);
      for (std::uint32_t i = run_first(r); i < w.run_end[run_first(r)]; ++i, ++s) {
        w.points[s] = {p[3 * std::size_t(i)], p[3 * std::size_t(i) + 1], p[3 * std::size_t(i) + 2], cube};
        w.column[s] = i;
      }
    }
  });
  w.cube_begin[cubes] = static_cast<std::uint32_t>(m);

  // Per cube and row, the range of occupied cubes the row covers; the anchor: the point nearest the cube
  // centre, ties to the earliest sorted position.
  const int rows = detail::csnb_rows(layout);
  w.spans.assign(cubes * rows * 2, 0);
  w.anchor.resize(cubes);
  // detail::csnb_row with the row's (dy, dz) looked up instead of divided out (two divisions per row).
  const int side = 2 * layout.reach + 1, top = (1 << layout.grid_exponent) - 1, n_exp = layout.grid_exponent;
  std::vector<int> row_dy(rows), row_dz(rows);
  for (int r = 0; r < rows; ++r) {
    row_dy[r] = r % side - layout.reach;
    row_dz[r] = r / side - layout.reach;
  }
  auto row_of = [&](std::uint32_t key, int r, std::uint32_t* lo, std::uint32_t* hi) {
    const int cx = int(key) & top, y = ((int(key) >> n_exp) & top) + row_dy[r],
              z = ((int(key) >> (2 * n_exp)) & top) + row_dz[r];
    if (y < 0 || y > top || z < 0 || z > top) return false;
    const int x0 = std::max(cx - layout.reach, 0), x1 = std::min(cx + layout.reach, top);
    const std::uint32_t base = std::uint32_t(y << n_exp) | std::uint32_t(z << (2 * n_exp));
    *lo = base | std::uint32_t(x0);
    *hi = base | std::uint32_t(x1);
    return true;
  };
  const int cube_parts = detail::parts_for(cubes, threads, 1024);
  detail::parallel_for(cubes, cube_parts, [&](std::size_t b, std::size_t e, int) {
    // Per row the searched key ranges grow with the cube, so two pointers per row walk the cube table.
    std::vector<std::uint32_t> lo_at(rows, 0), hi_at(rows, 0);
    bool started = false;
    const std::uint32_t* keys = w.cube_key.data();
    for (std::size_t c = b; c < e; ++c) {
      for (int r = 0; r < rows; ++r) {
        std::uint32_t lo, hi;
        if (!row_of(keys[c], r, &lo, &hi)) continue;
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
        w.spans[(c * rows + r) * 2] = c0;
        w.spans[(c * rows + r) * 2 + 1] = c1;
      }
      started = true;
      std::uint32_t best = w.cube_begin[c];
      const Point* q = w.points.data();
      double best_d = detail::centre_sq_dist(layout, keys[c], q[best].x, q[best].y, q[best].z);
      for (std::uint32_t s = best + 1; s < w.cube_begin[c + 1]; ++s) {
        const double d = detail::centre_sq_dist(layout, keys[c], q[s].x, q[s].y, q[s].z);
        if (d < best_d) {
          best_d = d;
          best = s;
        }
      }
      w.anchor[c] = best;
    }
  });

  w.is_anchor.assign(m, 0);
  for (std::size_t c = 0; c < cubes; ++c) w.is_anchor[w.anchor[c]] = 1;

  // Batches follow one random order of the non-anchor points, fixed by the seed. A point that is not marked
  // can never be marked again (counts only fall), and deleted points never return, so the points the walk
  // has passed are settled, and the first K marked points after the cursor are a uniformly random K-subset
  // of all marked points: the same law as drawing K at random in every iteration, without a full pass each.
  // A point's mark is counted when the walk reaches it, on the live set of that moment (the batch being
  // gathered is deleted only once complete), which is exactly what per-point neighbour counts kept up to
  // date by decrements would say; a point found unmarked stays settled.
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
          w.items[first++] = detail::csnb_priority(config.seed, w.column[s], static_cast<std::uint32_t>(s));
        }
      });
  w.order.assign(w.items.begin(), w.items.begin() + order_size);
  detail::radix_sort(w.order, w.scratch, 32, 64, [](std::uint64_t v) { return v; }, threads);
  w.walk_of.resize(m);
  w.walk_points.resize(m);
  detail::parallel_for(m, detail::parts_for(m, threads, 16384), [&](std::size_t b, std::size_t e, int) {
    for (std::size_t i = b; i < e; ++i) {
      const std::uint32_t s = i < order_size ? static_cast<std::uint32_t>(w.order[i]) : w.anchor[i - order_size];
      w.walk_of[s] = static_cast<std::uint32_t>(i);
      w.walk_points[i] = w.points[s];
    }
  });
  w.state.assign(m, kLive);
  w.slot_of.resize(m);
  init_candidates(w, cubes, rows, threads);
  Evaluator eval{w.walk_points.data(), w.candidates.data(), w.start.data(), w.row_slots.data(), rows,
                 layout.reach + layout.reach * side, layout.radius_sq, config.max_neighbours};

  // The walk is evaluated ahead in windows, in parallel: within a batch the live set does not change, so
  // every mark in the window is the one the sequential walk would count. Marked points past the (K+1)-th are
  // evaluated again later; unmarked ones are settled at once (they would be found unmarked later too).
  const std::size_t K = static_cast<std::size_t>(config.batch_size);
  w.result.resize(order_size);
  std::size_t alive = m, dead_since = 0, window = K + 1;
  auto evaluate = [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      if (i + 12 < e) eval.prefetch_rows(static_cast<std::uint32_t>(i + 12));
      if (i + 4 < e) eval.prefetch_centre(static_cast<std::uint32_t>(i + 4));
      w.result[i] = w.state[i] != kLive ? kSkip : eval.marked(static_cast<std::uint32_t>(i)) ? kMarked : kUnmarked;
    }
  };
  for (std::size_t cursor = 0;;) {
    w.batch.clear();
    std::size_t i = cursor, next = order_size;
    while (i < order_size && next == order_size) {
      const std::size_t end = std::min(order_size, i + window);
      const int eval_parts = detail::parts_for(end - i, threads, 256);
      detail::parallel_for(end - i, eval_parts, [&](std::size_t b, std::size_t e, int) { evaluate(i + b, i + e); });
      for (std::size_t j = i; j < end; ++j) {
        if (w.result[j] == kUnmarked) {
          w.state[j] = kSettled;
        } else if (w.result[j] == kMarked && next == order_size) {
          if (w.batch.size() == K)
            next = j;
          else
            w.batch.push_back(static_cast<std::uint32_t>(j));
        }
      }
      // Next window: enough positions for the marks still wanted (the rest of this batch, or all K + 1 of
      // the next one) at the rate seen so far, plus a margin.
      const std::size_t wanted_marks = next != order_size ? K + 1 : K + 1 - w.batch.size();
      const double rate = double(w.batch.size() + 1) / double((next != order_size ? next : end) - cursor);
      const double wanted = 1.2 * double(wanted_marks) / rate;
      window = std::max<std::size_t>(256, static_cast<std::size_t>(wanted));
      i = end;
    }
    for (std::uint32_t id : w.batch) {  // the last batch (K or fewer marked) deletes all still marked
      w.state[id] = kDead;
      w.candidates[w.slot_of[id]].x = std::numeric_limits<float>::quiet_NaN();
    }
    alive -= w.batch.size();
    dead_since += w.batch.size();
    if (next == order_size) break;
    if (dead_since * 2 > alive) {
      recompact(w, cubes, rows, threads);
      eval.candidates = w.candidates.data();
      eval.start = w.start.data();
      dead_since = 0;
    }
    cursor = next;
  }

  // Anchors still over the threshold (on the final live set) take their non-anchor neighbours with them.
  w.claims.assign(cubes, 0);
  detail::parallel_for(cubes, cube_parts, [&](std::size_t b, std::size_t e, int) {
    for (std::size_t c = b; c < e; ++c) w.claims[c] = eval.marked(static_cast<std::uint32_t>(order_size + c));
  });
  const float r2 = layout.radius_sq;
  for (std::size_t c = 0; c < cubes; ++c) {
    if (!w.claims[c]) continue;
    const Point a = w.walk_points[order_size + c];
    const std::uint32_t* slots = &w.row_slots[c * rows * 2];
    for (int r = 0; r < rows; ++r) {
      for (std::uint32_t j = slots[2 * r]; j < slots[2 * r + 1]; ++j) {
        const Candidate& n = w.candidates[j];  // deleted ones have x = NaN: never nearer than r2
        if (n.id < order_size && detail::sq_dist(a.x, a.y, a.z, n.x, n.y, n.z) < r2) w.state[n.id] = kDead;
      }
    }
  }
  const Point* q = w.points.data();

  // Kept points in sorted order.
  w.result.resize(m);
  Eigen::Matrix3Xf out;
  parallel_compact(
      m, threads, 16384,
      [&](std::size_t b, std::size_t e) {
        std::size_t kept = 0;
        for (std::size_t s = b; s < e; ++s) kept += w.result[s] = w.state[w.walk_of[s]] != kDead;
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

}  // namespace stvl::filter

#include "filter/detail/csnb_walk.hpp"

#include <algorithm>
#include <limits>

#include "filter/detail/common.hpp"

namespace stvl::filter::detail::csnb {

namespace {

constexpr std::size_t kWindowBatches = 8;  // batches per window of the walk

// Cube boundaries of `parts` parts with about equal candidates (start: each cube's first), rather than equal
// cubes: dense cubes cost more.
std::vector<std::size_t> split_cubes(const std::uint32_t* start, std::size_t cubes, int parts) {
  std::vector<std::size_t> part(parts + 1, cubes);
  for (int t = 0; t < parts; ++t) {
    const std::uint64_t target = std::uint64_t(start[cubes]) * std::uint64_t(t) / std::uint64_t(parts);
    part[t] = static_cast<std::size_t>(std::lower_bound(start, start + cubes, target) - start);
  }
  return part;
}

// Sizes `candidates` to n followed by kPad entries never within r.
void pad(std::vector<Candidate>& candidates, std::size_t n) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  candidates.resize(n + kPad);
  std::fill(candidates.begin() + n, candidates.end(), Candidate{nan, nan, nan, 0});
}

// Set bits of `bits` in [from, to).
std::size_t count_bits(const std::uint64_t* bits, std::size_t from, std::size_t to) {
  if (from >= to) return 0;
  const std::size_t first = from / 64, last = (to - 1) / 64;
  const std::uint64_t head = ~std::uint64_t{0} << (from % 64), tail = ~std::uint64_t{0} >> (63 - (to - 1) % 64);
  if (first == last) return std::size_t(__builtin_popcountll(bits[first] & head & tail));
  std::size_t n =
      std::size_t(__builtin_popcountll(bits[first] & head)) + std::size_t(__builtin_popcountll(bits[last] & tail));
  for (std::size_t k = first + 1; k < last; ++k) n += std::size_t(__builtin_popcountll(bits[k]));
  return n;
}
// The position of the k-th (from 1) set bit at or after `from` (there must be one).
std::size_t select_bit(const std::uint64_t* bits, std::size_t from, std::size_t k) {
  std::size_t word = from / 64;
  std::uint64_t v = bits[word] & (~std::uint64_t{0} << (from % 64));
  for (std::size_t c; (c = std::size_t(__builtin_popcountll(v))) < k; v = bits[++word]) k -= c;
  for (; k > 1; --k) v &= v - 1;
  return word * 64 + std::size_t(__builtin_ctzll(v));
}

}  // namespace

void find_sure(Workspace& w, const Counter& counter, std::size_t cubes, std::uint32_t order_size, bool avx2,
               int threads) {
  const std::size_t words = (std::size_t(order_size) + 63) / 64;
  const int parts = detail::parts_for(cubes, threads, 1024);
  w.sure_parts.resize(2 * parts);
  const std::vector<std::size_t> part = split_cubes(counter.start, cubes, parts);
  detail::parallel_for(std::size_t(parts), parts, [&](std::size_t, std::size_t, int t) {
    const std::size_t b = part[t], e = part[t + 1];
    std::vector<std::uint64_t>& sure = w.sure_parts[2 * t];  // bitmaps per part: no shared cache lines
    std::vector<std::uint64_t>& sparse = w.sure_parts[2 * t + 1];
    sure.assign(words, 0);
    sparse.assign(words, 0);
    sure_part(avx2, counter, b, e, order_size, sure.data(), sparse.data());
  });
  w.sure.assign(words, 0);
  w.sparse.assign(words, 0);
  detail::parallel_for(words, detail::parts_for(words, threads, 4096), [&](std::size_t b, std::size_t e, int) {
    for (int t = 0; t < parts; ++t) {
      for (std::size_t i = b; i < e; ++i) {
        w.sure[i] |= w.sure_parts[2 * t][i];
        w.sparse[i] |= w.sure_parts[2 * t + 1][i];
      }
    }
  });
}

void init_candidates(Workspace& w, std::size_t order_size, std::uint32_t never, int threads) {
  const std::size_t m = w.points.size();
  pad(w.candidates, m);
  detail::parallel_for(m, detail::parts_for(m, threads, 16384), [&](std::size_t b, std::size_t e, int) {
    for (std::size_t s = b; s < e; ++s) w.candidates[s] = {w.points[s].x, w.points[s].y, w.points[s].z, never};
  });
  detail::parallel_for(order_size, detail::parts_for(order_size, threads, 16384),
                       [&](std::size_t b, std::size_t e, int) {
                         for (std::size_t i = b; i < e; ++i) {
                           if (i + 16 < e)
                             __builtin_prefetch(&w.candidates[std::uint32_t(w.order[i + 16])], 1);  // a scatter
                           w.candidates[std::uint32_t(w.order[i])].key = static_cast<std::uint32_t>(i);
                         }
                       });
}

void settle(Workspace& w, std::uint32_t j, std::uint32_t never) {
  const std::uint32_t s = static_cast<std::uint32_t>(w.order[j]);  // its sorted position
  w.candidates[s].key = never;
  set_bit(w.settled_bits.data(), s);
}

namespace {

// walk()'s state: the current batch (from walk id `start`, `in_batch` marks in it), the marks so far, and the
// window of unsure points classified ahead (w.result up to window_end).
class Walker {
 public:
  Walker(Workspace& w, const Counter& counter, std::size_t order_size, std::size_t K, bool avx2, int threads)
      : w_(w), counter_(counter), order_size_(order_size), K_(K), avx2_(avx2), threads_(threads) {}

  // n more marks, the sure points at walk ids [from, to): where the last batch they start begins.
  void sure_marks(std::size_t from, std::size_t to) {
    const std::uint64_t* sure = w_.sure.data();
    const std::size_t n = count_bits(sure, from, to);
    marks_ += n;
    if (in_batch_ + n <= K_) {
      in_batch_ += n;
      return;
    }
    const std::size_t first = K_ - in_batch_ + 1;  // the first of them that starts a batch (from 1), then every K
    const std::size_t last = first + (n - first) / K_ * K_;
    start_ = static_cast<std::uint32_t>(select_bit(sure, from, last));
    in_batch_ = n - last + 1;
  }

  // Whether unsure point k (walk id j) is marked when the walk reaches it: counted in its batch (the window's
  // verdicts hold whatever was deleted since it opened); a (K+1)-th mark deletes the batch and is counted again.
  bool reach(std::size_t k) {
    if (k >= window_end_) open_window(k);
    const std::uint32_t j = w_.unsure[k];
    const std::uint8_t verdict = w_.result[k];
    bool marked = verdict == kMarked || (verdict == kAmbiguous && marked_exactly(k));
    if (marked && in_batch_ == K_) {  // j is the (K+1)-th mark: the batch is deleted and j counted again
      start_ = j;
      in_batch_ = 0;
      marked = verdict == kMarked || marked_exactly(k);
    }
    if (marked) {
      ++in_batch_;
      ++marks_;
    }
    return marked;
  }

 private:
  bool marked_exactly(std::size_t k) const {
    return marked_now(avx2_, counter_, w_.unsure_points[k], start_, w_.unsure[k]);
  }

  // The unsure points from index `from` of w.unsure that lie within about kWindowBatches batches, classified.
  void open_window(std::size_t from) {
    const std::size_t unsure = w_.unsure.size();
    const std::uint32_t first = w_.unsure[from];
    const double rate = first == 0 ? 1.0 : double(marks_) / double(first);  // marks per walk position so far
    const double span = double(kWindowBatches * (K_ + 1)) / std::max(rate, 1e-3);
    const double last = std::min(double(order_size_), double(first) + std::max(span, 256.0));
    window_end_ = from;
    while (window_end_ < unsure && double(w_.unsure[window_end_]) < last) ++window_end_;
    const std::size_t n = window_end_ - from;
    const std::uint32_t start = start_;
    detail::parallel_for(n, detail::parts_for(n, threads_, 128), [&](std::size_t b, std::size_t e, int) {
      classify(avx2_, counter_, w_.unsure_points.data() + from, start, w_.unsure.data() + from, b, e,
               w_.result.data() + from);
    });
  }

  Workspace& w_;
  const Counter& counter_;
  const std::size_t order_size_, K_;
  const bool avx2_;
  const int threads_;
  std::uint32_t start_ = 0;     // walk id where the current batch starts
  std::size_t in_batch_ = 0;    // marks in it
  std::size_t marks_ = 0;       // marks so far
  std::size_t window_end_ = 0;  // index into w.unsure
};

}  // namespace

// The walk, over the points neither sure nor sparse (w.unsure, by walk id) in windows of about
// kWindowBatches batches; the sure points in between are counted from their bits, as marks that fill the
// batches. Points of a window are first classified in parallel when it opens (classify): with more than
// max_neighbours safe neighbours (anchors, settled, later in the walk: none can be deleted before the walk
// reaches the point) they are marked whenever reached; with no more than that many live ones they are
// unmarked then (counts only fall) and settled; the rest (ambiguous) are counted exactly when the walk
// reaches them, in the batch of that moment. A batch is deleted when the mark after its K-th arrives, which
// starts the next: nothing needs doing then but moving `start`, since the candidates' keys say who is live.
void walk(Workspace& w, Counter& counter, std::size_t order_size, std::size_t K, std::uint32_t never, bool avx2,
          int threads) {
  w.result.resize(w.unsure.size());
  Walker walker(w, counter, order_size, K, avx2, threads);
  std::size_t previous = 0;  // walk id after the last unsure point
  for (std::size_t k = 0; k < w.unsure.size(); ++k) {
    const std::uint32_t j = w.unsure[k];
    walker.sure_marks(previous, j);
    previous = std::size_t(j) + 1;
    if (!walker.reach(k)) settle(w, j, never);
  }
}

// Anchors still over the threshold (on the final live set) take their non-anchor neighbours with them. All
// live points are now anchors or settled: an anchor's count is the anchors near it, counted over the
// anchors alone (one per cube, so cube ranges are anchor ranges), plus the settled points near it.
void claim(Workspace& w, const Counter& counter, std::size_t cubes, bool avx2, int threads) {
  const int cube_parts = detail::parts_for(cubes, threads, 1024);
  pad(w.anchor_candidates, cubes);
  w.cube_index.resize(cubes + 1);
  detail::parallel_for(cubes + 1, cube_parts, [&](std::size_t b, std::size_t e, int) {
    for (std::size_t c = b; c < e; ++c) {
      w.cube_index[c] = static_cast<std::uint32_t>(c);
      if (c == cubes) break;
      const Point& a = w.points[w.anchor[c]];
      w.anchor_candidates[c] = {a.x, a.y, a.z, static_cast<std::uint32_t>(c)};
    }
  });
  const int rows = counter.rows;
  const Counter anchors{w.anchor_candidates.data(), w.cube_index.data(), w.spans.data(),   rows,
                        counter.centre_row,         counter.r2,          counter.threshold};
  // The anchors near a settled point (sorted position s).
  auto near_anchors = [&](std::size_t s, auto&& visit) {
    const Point& q = w.points[s];
    const std::uint32_t* span = &w.spans[std::size_t(q.cube) * rows * 2];
    for (int r = 0; r < rows; ++r) {
      for (std::uint32_t c = span[2 * r]; c < span[2 * r + 1]; ++c) {
        const Candidate& a = w.anchor_candidates[c];
        if (detail::sq_dist(q.x, q.y, q.z, a.x, a.y, a.z) < counter.r2) visit(c);
      }
    }
  };
  // The settled points (set by the walk as bits by sorted position), listed in cube order.
  w.settled.clear();
  for_each_bit(w.settled_bits, [&](std::uint32_t s) { w.settled.push_back(s); });
  const std::size_t settled_count = w.settled.size();
  const int settled_parts = detail::parts_for(settled_count, threads, 2048);
  w.settled_near.resize(settled_parts);
  w.near_pairs.resize(settled_parts);
  detail::parallel_for(settled_count, settled_parts, [&](std::size_t b, std::size_t e, int t) {
    std::vector<std::uint32_t>& near = w.settled_near[t];  // per part: no shared counters
    std::vector<std::uint64_t>& pairs = w.near_pairs[t];   // (settled point, anchor), for the claims below
    near.assign(cubes, 0);
    pairs.clear();
    for (std::size_t k = b; k < e; ++k) {
      if (k + 8 < e) anchors.prefetch_spans(w.points[w.settled[k + 8]].cube);
      if (k + 4 < e) anchors.prefetch_rows(w.points[w.settled[k + 4]].cube);
      near_anchors(w.settled[k], [&](std::uint32_t c) {
        ++near[c];
        pairs.push_back(std::uint64_t{w.settled[k]} << 32 | c);
      });
    }
  });
  for (int t = 1; t < settled_parts; ++t)
    for (std::size_t c = 0; c < cubes; ++c) w.settled_near[0][c] += w.settled_near[t][c];
  w.claims.resize(cubes);
  detail::parallel_for(cubes, cube_parts, [&](std::size_t b, std::size_t e, int) {
    anchors_over(avx2, anchors, w.settled_near[0].data(), b, e, w.claims.data());
  });
  w.claimed.assign(w.points.size(), 0);
  detail::parallel_for(std::size_t(settled_parts), settled_parts, [&](std::size_t, std::size_t, int t) {
    for (const std::uint64_t pair : w.near_pairs[t]) {  // a settled point is in one part only
      if (w.claims[std::uint32_t(pair)]) w.claimed[pair >> 32] = 1;
    }
  });
}

}  // namespace stvl::filter::detail::csnb

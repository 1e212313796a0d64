#pragma once
// CSNB's walk over the random order and the anchors' final claims (csnb_walk.cpp), on the buffers the driver
// (csnb.cpp) fills.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "filter/detail/csnb_count.hpp"

namespace stvl::filter::detail::csnb {

// Buffers kept per calling thread (see voxel_grid.cpp): fresh ones would page-fault on every frame.
struct Workspace {
  std::vector<std::uint64_t> items, scratch, order;
  std::vector<std::uint32_t> column, cube_key, cube_begin, spans, anchor, unsure;
  std::vector<Point> points, unsure_points;
  std::vector<Candidate> candidates;
  std::vector<std::uint64_t> sure;                     // bit per walk id: marked whenever reached (find_sure)
  std::vector<std::uint64_t> sparse;                   // bit per walk id: no more than max_neighbours neighbours at all
  std::vector<std::vector<std::uint64_t>> sure_parts;  // per part of find_sure: sure, sparse, sure, ...
  std::vector<std::uint8_t> is_anchor, result, claims, claimed;
  std::vector<Candidate> anchor_candidates;  // by cube, for the final claims
  std::vector<std::uint32_t> cube_index;
  std::vector<std::vector<std::uint32_t>> settled_near;  // per part: settled points near each anchor
  std::vector<std::uint64_t> settled_bits;
  std::vector<std::uint32_t> settled;  // sorted positions
  std::vector<std::vector<std::uint64_t>> near_pairs;
};

// Fills w.sure and w.sparse (bits by walk id) from the counts of every point, all candidates live.
void find_sure(Workspace& w, const Counter& counter, std::size_t cubes, std::uint32_t order_size, bool avx2,
               int threads);
// The candidates: every point, keyed by its walk id (never for anchors).
void init_candidates(Workspace& w, std::size_t order_size, std::uint32_t never, int threads);
// Settles the point of walk id j: live to the end, never deleted.
void settle(Workspace& w, std::uint32_t j, std::uint32_t never);
// The batches, over the points neither sure nor sparse (w.unsure, by walk id): settles the points the walk
// finds unmarked; the others are deleted.
void walk(Workspace& w, Counter& counter, std::size_t order_size, std::size_t K, std::uint32_t never, bool avx2,
          int threads);
// Anchors still over the threshold take their non-anchor neighbours with them: sets w.claimed.
void claim(Workspace& w, const Counter& counter, std::size_t cubes, bool avx2, int threads);

}  // namespace stvl::filter::detail::csnb

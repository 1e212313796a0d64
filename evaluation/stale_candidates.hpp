#pragma once
// Where stale map voxels can be, for the clearing latency of moved bodies (evaluator.hpp): the voxels a moving body
// has occupied (Truth::vacated()) that are now far from every true surface (near neither a static body nor a moving
// one, at the tolerance). Kept up to date incrementally: after truth updates only the voxels they touched
// (Truth::take_touched(): newly vacated ones, and the moving bodies' surroundings before and after) are looked at
// again, where rebuilding visits every vacated voxel (all the places the people ever walked). The plain rebuild,
// reference::stale_candidates() (reference/stale_candidates.hpp), is compared with it in
// tests/evaluation/test_stale_candidates.cpp.
#include <vector>

#include "common/voxel_key.hpp"
#include "evaluation/truth.hpp"
#include "evaluation/voxel_mask_set.hpp"

namespace stvl::evaluation {

class StaleCandidates {
 public:
  // Brings the set to truth's current state (takes truth's touched voxels).
  void update(Truth& truth);
  // Whether key is a candidate (a bit test where the last one was in the same 8^3 leaf: one thread at a time).
  bool contains(const VoxelKey& key) const { return keys_.contains(key); }
  // The candidates, as a set (a copy).
  VoxelSet keys() const;
  // A box (keys, each axis) holding every candidate; it never shrinks, so it may hold former ones. Empty: lo > hi.
  const VoxelKey& lo() const { return lo_; }
  const VoxelKey& hi() const { return hi_; }

 private:
  VoxelMaskSet keys_;
  VoxelMaskSet asked_static_, near_static_;  // static truth does not move: asked once
  std::vector<VoxelKey> touched_;
  VoxelKey lo_{1, 1, 1}, hi_{0, 0, 0};
};

// Sorts distinct vacated voxels by their place in truth.vacated()'s iteration (the order clearing records them in,
// which the latencies' sums follow).
void sort_in_vacated_order(const Truth& truth, std::vector<VoxelKey>& keys);

}  // namespace stvl::evaluation

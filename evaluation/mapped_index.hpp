#pragma once
// evaluate()'s mapped-voxel phase kept from one evaluation to the next. Per leaf of the map (8^3 voxels, the
// map's own masks: VoxelMap::for_each_leaf) each voxel's results are remembered: its static-truth
// neighbourhood test (never changes), its moving-truth test (per truth version) and its surface distance
// (per truth version, or for good where only static geoms decide it: Truth::voxel_distance_to_surface_m's
// *fixed).
// An evaluation reads the leaf masks and computes only voxels it has no valid result for, so a map that
// changed little costs a mask walk. The figures equal reference::match_mapped()'s (the definition, in
// evaluation/reference/mapped_index.hpp; tests only).
#include <array>
#include <cstdint>
#include <map>
#include <unordered_map>
#include <utility>
#include <vector>

#include "common/voxel_key.hpp"
#include "evaluation/metrics.hpp"
#include "evaluation/truth.hpp"
#include "mapping/voxel_map.hpp"

namespace stvl::evaluation {

class MappedIndex {
 public:
  // The same counts as reference::match_mapped(map, truth, tol, ...) at the truth's tolerance_voxels (its
  // near_static() and near_moving()); the distances pooled inside (distance_counts()).
  VoxelMatches match(const mapping::VoxelMap& map, Truth& truth);
  // Computes the results match() will need for the map as it is now (between evaluations, so that an
  // evaluation finds little left to compute); counts nothing. Optional: match() alone gives the same figures.
  void update(const mapping::VoxelMap& map, Truth& truth);
  // Every distance counted so far: distance -> count (as reference::match_mapped's map after the same calls).
  std::map<double, std::size_t> distance_counts() const;
  // The map as of the last match(): whether key is in it, and whether a voxel within tol (Chebyshev) is.
  bool contains(const VoxelKey& key) const;
  bool near(const VoxelKey& key, int tol) const;
  // Leaves remembered (8^3 voxels each): the map's at the last match(), plus any that update() added since.
  std::size_t leaves() const { return leaves_.size(); }

 private:
  using Mask = std::array<std::uint64_t, 8>;
  struct Leaf {
    Mask on{};                               // the map's voxels at the last match()
    Mask static_done{}, static_near{};       // truth.near_static(), once per voxel
    Mask moving_done{}, moving_near{};       // truth.near_moving(), at `version`
    Mask distance_done{}, distance_fixed{};  // distance_id valid (at `version`, or for good where fixed)
    std::size_t version = 0;
    std::size_t stamp = 0;  // the last match() that saw the leaf in the map
    VoxelKey origin;
    Leaf* next = nullptr;  // the leaf after it in the last walk's (the tree's) order: most walks find it there
    std::array<std::uint32_t, 512> distance_id;  // into distances_; kNoDistance when there is none
  };
  static constexpr std::uint32_t kNoDistance = 0xffffffffu;
  std::uint32_t intern(double d);
  void walk(const mapping::VoxelMap& map, Truth& truth, VoxelMatches* counts);  // counts: match() only
  // walk()'s phases: a leaf's masks of the truth's version (its distances queued), the queued distances (in
  // parallel), the pooled counts of match().
  void visit_leaf(Leaf& leaf, const std::uint64_t* on, Truth& truth, std::size_t version);
  void compute_distances(const Truth& truth);
  void count_matches(VoxelMatches& counts);
  const Leaf* leaf_of(const VoxelKey& key) const;

  std::unordered_map<VoxelKey, Leaf, VoxelKeyHash> leaves_;  // by origin
  Leaf* first_ = nullptr;                                    // the last walk's first leaf
  std::size_t stamp_ = 0;
  std::vector<double> distances_;    // distinct distances, by id
  std::vector<std::size_t> counts_;  // pooled count per id
  std::unordered_map<double, std::uint32_t> distance_ids_;
  std::vector<std::pair<Leaf*, int>> distance_todo_;  // walk(): the voxels whose distance is to compute
  mutable const Leaf* last_leaf_ = nullptr;           // near(): neighbours mostly share a leaf
  mutable VoxelKey last_origin_{1, 1, 1};
};

}  // namespace stvl::evaluation

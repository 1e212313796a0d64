#pragma once
// A set of voxel keys stored as 8^3-voxel leaves of 512 bits (the map's own layout): membership tests that fall in
// the leaf of the previous one cost a bit test, where a VoxelSet costs a hash lookup that mostly misses the cache
// (Truth's static voxels at 0.02 m are millions). Same answers as a VoxelSet holding the same keys
// (tests/evaluation/test_mapped_index.cpp compares them). Not safe for concurrent contains(): it caches a leaf.
// A key may carry a label (Truth's body index): one per leaf where all its keys share it, as most do; the keys of
// leaves with several labels keep theirs in a map. The first label given to a key stays, as with emplace().
#include <array>
#include <cstdint>
#include <unordered_map>

#include "common/voxel_key.hpp"

namespace stvl::evaluation {

class VoxelMaskSet {
 public:
  // Adds key with label (-1: none); a key already present keeps its first label.
  void insert(const VoxelKey& key, int label = -1) {
    const VoxelKey origin = origin_of(key);
    bool fresh = false;
    if (origin != last_origin_ || !last_) {  // a rehash moves no leaf: the cached one stays valid
      const auto emplaced = leaves_.try_emplace(origin);
      fresh = emplaced.second;
      last_origin_ = origin, last_ = &emplaced.first->second;
    }
    Leaf& leaf = *last_;
    const int i = offset_of(key);
    const bool had = (leaf.on[i >> 6] >> (i & 63)) & 1u;
    leaf.on[i >> 6] |= std::uint64_t{1} << (i & 63);
    if (fresh) leaf.label = label;
    if (leaf.label == kMixed) mixed_.emplace(key, label);
    else if (!had && leaf.label != label) {  // a second label in this leaf: every key keeps its own from now on
      for_each_in(origin, leaf, [&](const VoxelKey& k) { mixed_.emplace(k, k == key ? label : leaf.label); });
      leaf.label = kMixed;
    }
  }
  // Removes key (and its label); an empty leaf stays, holding no key.
  void erase(const VoxelKey& key) {
    Leaf* leaf = leaf_of(key);
    const int i = offset_of(key);
    if (!leaf || !((leaf->on[i >> 6] >> (i & 63)) & 1u)) return;
    leaf->on[i >> 6] &= ~(std::uint64_t{1} << (i & 63));
    if (leaf->label == kMixed) mixed_.erase(key);
  }
  // Whether key is in the set.
  bool contains(const VoxelKey& key) const {
    const Leaf* leaf = leaf_of(key);
    const int i = offset_of(key);
    return leaf && ((leaf->on[i >> 6] >> (i & 63)) & 1u);
  }
  // The key's label; absent keys: -1.
  int label_of(const VoxelKey& key) const {
    const Leaf* leaf = leaf_of(key);
    const int i = offset_of(key);
    if (!leaf || !((leaf->on[i >> 6] >> (i & 63)) & 1u)) return -1;
    return leaf->label != kMixed ? leaf->label : mixed_.at(key);
  }
  // f(key) for every key, leaf by leaf (unordered).
  template <class F>
  void for_each(F&& f) const {
    for (const auto& [origin, leaf] : leaves_) for_each_in(origin, leaf, f);
  }
  // Removes every key and label.
  void clear() { leaves_.clear(), mixed_.clear(), last_origin_ = {1, 1, 1}, last_ = nullptr; }

 private:
  static constexpr int kMixed = -2;
  struct Leaf {
    std::array<std::uint64_t, 8> on{};
    int label = -1;  // every key's, or kMixed: see mixed_
  };
  static VoxelKey origin_of(const VoxelKey& k) { return {k.x & ~7, k.y & ~7, k.z & ~7}; }
  static int offset_of(const VoxelKey& k) { return ((k.x & 7) << 6) | ((k.y & 7) << 3) | (k.z & 7); }
  template <class F>
  static void for_each_in(const VoxelKey& origin, const Leaf& leaf, F&& f) {
    for (int w = 0; w < 8; ++w)
      for (std::uint64_t bits = leaf.on[w]; bits; bits &= bits - 1) {
        const int i = 64 * w + __builtin_ctzll(bits);
        f(VoxelKey{origin.x + (i >> 6), origin.y + ((i >> 3) & 7), origin.z + (i & 7)});
      }
  }
  Leaf* leaf_of(const VoxelKey& key) const {
    const VoxelKey origin = origin_of(key);
    if (origin != last_origin_) {
      const auto it = leaves_.find(origin);
      last_origin_ = origin;
      last_ = it == leaves_.end() ? nullptr : const_cast<Leaf*>(&it->second);
    }
    return last_;
  }

  std::unordered_map<VoxelKey, Leaf, VoxelKeyHash> leaves_;
  std::unordered_map<VoxelKey, int, VoxelKeyHash> mixed_;  // the keys of leaves with several labels
  mutable VoxelKey last_origin_{1, 1, 1};                  // no leaf's origin
  mutable Leaf* last_ = nullptr;                           // its leaf, or null where there is none
};

}  // namespace stvl::evaluation

#pragma once
// A set of voxel keys stored as 8^3-voxel leaves of 512 bits (the map's own layout): membership tests that fall in
// the leaf of the previous one cost a bit test, where a VoxelSet costs a hash lookup that mostly misses the cache
// (Truth's static voxels at 0.02 m are millions). Same answers as a VoxelSet holding the same keys
// (tests/evaluation/test_mapped_index.cpp compares them). Not safe for concurrent contains(): it caches a leaf.
#include <array>
#include <cstdint>
#include <unordered_map>

#include "common/voxel_key.hpp"

namespace stvl::evaluation {

class VoxelMaskSet {
 public:
  void insert(const VoxelKey& key) {
    auto& leaf = leaves_[origin_of(key)];
    const int i = offset_of(key);
    leaf[i >> 6] |= std::uint64_t{1} << (i & 63);
    last_origin_ = {1, 1, 1}, last_ = nullptr;  // insertion may rehash: pointers stay, the cache is reset anyway
  }
  bool contains(const VoxelKey& key) const {
    const VoxelKey origin = origin_of(key);
    if (origin != last_origin_) {
      const auto it = leaves_.find(origin);
      last_origin_ = origin;
      last_ = it == leaves_.end() ? nullptr : &it->second;
    }
    if (!last_) return false;
    const int i = offset_of(key);
    return ((*last_)[i >> 6] >> (i & 63)) & 1u;
  }
  void clear() { leaves_.clear(), last_origin_ = {1, 1, 1}, last_ = nullptr; }

 private:
  using Leaf = std::array<std::uint64_t, 8>;
  static VoxelKey origin_of(const VoxelKey& k) { return {k.x & ~7, k.y & ~7, k.z & ~7}; }
  static int offset_of(const VoxelKey& k) { return ((k.x & 7) << 6) | ((k.y & 7) << 3) | (k.z & 7); }

  std::unordered_map<VoxelKey, Leaf, VoxelKeyHash> leaves_;
  mutable VoxelKey last_origin_{1, 1, 1};  // no leaf's origin
  mutable const Leaf* last_ = nullptr;
};

}  // namespace stvl::evaluation

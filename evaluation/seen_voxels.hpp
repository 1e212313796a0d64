#pragma once
// The voxels a noise-free camera saw within the recall window, each with the time it was last seen, kept as a
// vector sorted by key: a frame's sorted keys are merged in one pass, and an evaluation walks the voxels in key
// order (neighbours together, so the map mirror's lookups stay in one leaf).
#include <cstddef>
#include <vector>

#include "common/voxel_key.hpp"

namespace stvl::evaluation {

class SeenVoxels {
 public:
  struct Entry {
    static constexpr int kUnknown = -2;
    VoxelKey key;
    double time_s = 0;
    int static_body = kUnknown;  // Truth::static_body_of(key), remembered once asked (it never changes)
    bool off_truth = false;      // already counted among the off-truth voxels
  };

  // Records sorted, unique keys as seen at time_s (their entries keep what they remembered), forgets every voxel
  // last seen before oldest_s, and calls seen(entry) for each recorded key's entry.
  template <class Seen>
  void record(const std::vector<VoxelKey>& sorted_keys, double time_s, double oldest_s, Seen&& seen) {
    merged_.clear();
    merged_.reserve(entries_.size() + sorted_keys.size());
    auto old = entries_.begin();
    const auto keep_older = [&](const VoxelKey* until) {
      for (; old != entries_.end() && (!until || old->key < *until); ++old)
        if (old->time_s >= oldest_s) merged_.push_back(*old);
    };
    for (const VoxelKey& key : sorted_keys) {
      keep_older(&key);
      if (old != entries_.end() && old->key == key) merged_.push_back(*old++);
      else merged_.push_back(Entry{key});
      merged_.back().time_s = time_s;
      seen(merged_.back());
    }
    keep_older(nullptr);
    entries_.swap(merged_);
  }
  // Forgets every voxel last seen before oldest_s.
  void forget_before(double oldest_s);
  std::vector<Entry>& entries() { return entries_; }    // sorted by key
  std::size_t size() const { return entries_.size(); }  // voxels remembered

 private:
  std::vector<Entry> entries_, merged_;
};

}  // namespace stvl::evaluation

#include "evaluation/stale_candidates.hpp"

#include <algorithm>

namespace stvl::evaluation {

void StaleCandidates::update(Truth& truth) {
  truth.take_touched(touched_);
  for (const VoxelKey& k : touched_) {
    if (!truth.is_vacated(k)) continue;
    if (!asked_static_.contains(k)) {
      asked_static_.insert(k);
      if (truth.near_static(k)) near_static_.insert(k);
    }
    if (near_static_.contains(k) || truth.near_moving(k)) {
      keys_.erase(k);
      continue;
    }
    if (keys_.contains(k)) continue;
    keys_.insert(k);
    if (lo_.x > hi_.x) lo_ = hi_ = k;
    lo_ = {std::min(lo_.x, k.x), std::min(lo_.y, k.y), std::min(lo_.z, k.z)};
    hi_ = {std::max(hi_.x, k.x), std::max(hi_.y, k.y), std::max(hi_.z, k.z)};
  }
  touched_.clear();
}

VoxelSet StaleCandidates::keys() const {
  VoxelSet out;
  keys_.for_each([&](const VoxelKey& k) { out.insert(k); });
  return out;
}

void sort_in_vacated_order(const Truth& truth, std::vector<VoxelKey>& keys) {
  if (keys.size() < 2) return;
  std::unordered_map<VoxelKey, std::size_t, VoxelKeyHash> rank;
  for (const VoxelKey& k : keys) rank.emplace(k, 0);
  std::size_t r = 0, found = 0;
  for (const VoxelKey& k : truth.vacated()) {
    ++r;
    const auto it = rank.find(k);
    if (it == rank.end()) continue;
    it->second = r;
    if (++found == rank.size()) break;
  }
  std::sort(keys.begin(), keys.end(), [&](const VoxelKey& a, const VoxelKey& b) { return rank.at(a) < rank.at(b); });
}
}  // namespace stvl::evaluation

#include "evaluation/stale_candidates.hpp"

#include <algorithm>

namespace stvl::evaluation {

void StaleCandidates::update(Truth& truth) {
  truth.take_touched(touched_);
  for (const VoxelKey& k : touched_) {
    if (!truth.vacated().count(k)) continue;
    const auto [near_static, fresh] = near_static_.try_emplace(k, false);
    if (fresh) near_static->second = truth.near_static(k);
    if (near_static->second || truth.near_moving(k)) {
      keys_.erase(k);
      continue;
    }
    if (!keys_.insert(k).second) continue;
    if (lo_.x > hi_.x) lo_ = hi_ = k;
    lo_ = {std::min(lo_.x, k.x), std::min(lo_.y, k.y), std::min(lo_.z, k.z)};
    hi_ = {std::max(hi_.x, k.x), std::max(hi_.y, k.y), std::max(hi_.z, k.z)};
  }
  touched_.clear();
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

#include "evaluation/clearing.hpp"

#include <algorithm>
#include <numeric>

namespace stvl::evaluation {

void ClearingLatency::seen_through(const VoxelKey& key, double time_s) { first_seen_s_.emplace(key, time_s); }

void ClearingLatency::after_update(double time_s, const std::function<bool(const VoxelKey&)>& in_map) {
  for (auto it = first_seen_s_.begin(); it != first_seen_s_.end();) {
    if (in_map(it->first)) {
      ++it;
      continue;
    }
    latencies_s_.push_back(time_s - it->second);
    it = first_seen_s_.erase(it);
  }
}

ClearingResult ClearingLatency::result(double time_s) const {
  ClearingResult c;
  std::vector<double> latencies = latencies_s_;
  c.not_cleared = first_seen_s_.size();
  for (const auto& [key, first] : first_seen_s_) latencies.push_back(time_s - first);
  c.stale_voxels_seen_through = latencies.size();
  if (!latencies.empty()) {
    c.max_latency_s = *std::max_element(latencies.begin(), latencies.end());
    c.mean_latency_s = std::accumulate(latencies.begin(), latencies.end(), 0.0) / latencies.size();
  }
  return c;
}

}  // namespace stvl::evaluation

#pragma once
// Clearing latency of moved bodies. A map voxel where a moving body was, far from every true surface now, is
// "stale"; it is seen through once the noise-free depth at its pixel lies beyond it. Its latency runs from
// that moment until it leaves the map. A stale voxel never seen through counts neither as cleared nor as
// missed: the map cannot be blamed for what the camera did not show it.
#include <cstddef>
#include <functional>
#include <unordered_map>
#include <vector>

#include "common/voxel_key.hpp"

namespace stvl::evaluation {

struct ClearingResult {
  std::size_t stale_voxels_seen_through = 0;
  std::size_t not_cleared = 0;  // seen through but still in the map at the end
  double max_latency_s = 0;     // includes voxels never cleared (counted until the end)
  double mean_latency_s = 0;
};

class ClearingLatency {
 public:
  // Before the map's update with the frame at time_s: a stale voxel seen through now (the first time counts).
  void seen_through(const VoxelKey& key, double time_s);
  // Whether key was seen through and is still awaited: not yet found gone from the map by after_update().
  bool tracked(const VoxelKey& key) const { return first_seen_s_.count(key) > 0; }
  // After the map's update at time_s: every tracked voxel the map no longer holds is cleared now.
  void after_update(double time_s, const std::function<bool(const VoxelKey&)>& in_map);
  // Voxels still tracked at time_s are not cleared; their latency runs until time_s.
  ClearingResult result(double time_s) const;

 private:
  std::unordered_map<VoxelKey, double, VoxelKeyHash> first_seen_s_;  // tracked: seen through, still in the map
  std::vector<double> latencies_s_;                                  // cleared
};

}  // namespace stvl::evaluation

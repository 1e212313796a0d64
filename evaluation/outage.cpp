#include "evaluation/outage.hpp"

#include <algorithm>

namespace stvl::evaluation {
namespace {

std::uint64_t bit(std::size_t camera) { return camera < 64 ? std::uint64_t{1} << camera : 0; }

bool in_map(const mapping::VoxelMap& map, const VoxelKey& k, int tol) {
  return any_within(k, tol, [&](const VoxelKey& n) { return map.contains(n); });
}

}  // namespace

OutageMonitor::OutageMonitor(std::vector<std::vector<OutageWindow>> outages, int tolerance_voxels)
    : tolerance_voxels_(tolerance_voxels) {
  for (std::size_t c = 0; c < outages.size(); ++c)
    for (const auto& w : outages[c]) {
      Active a;
      a.result.camera_index = c;
      a.result.window = w;
      outages_.push_back(std::move(a));
    }
}

void OutageMonitor::observe(std::size_t camera, double time_s, const std::vector<VoxelKey>& keys, const Truth& truth,
                            std::size_t marking_points) {
  if (outages_.empty()) return;
  for (const VoxelKey& k : keys)
    if (truth.contains(k)) seen_by_[k] |= bit(camera);
  for (auto& a : outages_) {
    if (a.result.camera_index != camera) continue;
    const OutageWindow& w = a.result.window;
    if (time_s >= w.from_s && time_s < w.to_s) ++a.result.frames_in_window;
    if (time_s >= w.to_s && a.result.first_marking_frame_s < 0 && marking_points > 0)
      a.result.first_marking_frame_s = time_s;
  }
}

void OutageMonitor::before_update(double time_s, const mapping::VoxelMap& map) {
  for (auto& a : outages_) {
    if (a.started || time_s < a.result.window.from_s) continue;
    a.started = true;
    const std::uint64_t own = bit(a.result.camera_index);
    for (const auto& [k, cameras] : seen_by_)
      if (cameras == own && in_map(map, k, tolerance_voxels_)) a.watched.push_back(k);
    std::sort(a.watched.begin(), a.watched.end());
    a.result.only_seen_voxels = a.watched.size();
  }
}

void OutageMonitor::after_update(double time_s, const mapping::VoxelMap& map) {
  for (auto& a : outages_) {
    if (!a.started || a.ended) continue;
    if (time_s >= a.result.window.to_s) {
      a.ended = true;
      a.watched.clear();
      continue;
    }
    const std::uint64_t own = bit(a.result.camera_index);
    auto keep = a.watched.begin();
    for (const VoxelKey& k : a.watched) {
      if (seen_by_[k] != own) continue;  // another camera saw it since: no longer the stopped camera's alone
      if (!in_map(map, k, tolerance_voxels_)) {
        ++a.result.cleared;
        if (a.result.first_cleared_s < 0) a.result.first_cleared_s = time_s;
        continue;
      }
      *keep++ = k;
    }
    a.watched.erase(keep, a.watched.end());
  }
}

std::vector<OutageResult> OutageMonitor::results(const std::vector<EvaluationSnapshot>& snapshots) const {
  std::vector<OutageResult> all;
  for (const auto& a : outages_) {
    OutageResult r = a.result;
    const std::size_t c = r.camera_index;
    for (const auto& s : snapshots)
      if (s.time_s < r.window.from_s && c < s.cameras.size()) r.recall_before = s.cameras[c].recall;
    for (const auto& s : snapshots)
      if (s.time_s >= r.window.to_s && c < s.cameras.size() && r.recall_before > 0 &&
          s.cameras[c].recall >= OutageResult::kResumeFraction * r.recall_before) {
        r.recall_resumed_s = s.time_s;
        break;
      }
    all.push_back(r);
  }
  return all;
}

}  // namespace stvl::evaluation

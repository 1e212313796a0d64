#pragma once
// A camera that stops (scenario key outages): per outage of a camera, what the map lost of what only that
// camera had seen, and when the map resumed. Fed by the runner:
//   observe()       per frame, the truth voxels the noise-free camera saw (Evaluator::frame_keys());
//   before_update() with the map before each update, after_update() after it;
//   results()       at the end, with the evaluation's snapshots (per-camera recall).
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "common/voxel_key.hpp"
#include "evaluation/evaluator.hpp"
#include "mapping/voxel_map.hpp"

namespace stvl::evaluation {

struct OutageWindow {
  double from_s = 0, to_s = 0;  // [from_s, to_s): the camera publishes nothing
};

struct OutageResult {
  std::size_t camera_index = 0;
  OutageWindow window;
  std::size_t frames_in_window = 0;  // frames of this camera taken inside the window (0 when it really stopped)
  // Truth voxels in the map (within tolerance) just before the window's first update that this camera alone had
  // seen; of those, how many left the map during the window while no other camera saw them, and when first.
  std::size_t only_seen_voxels = 0, cleared = 0;
  double first_cleared_s = -1;
  double first_marking_frame_s = -1;  // the camera's first frame at or after to_s with points to mark; -1 none
  double recall_before = 0;           // its recall at the last evaluation before from_s (0: none)
  double recall_resumed_s = -1;       // first evaluation at or after to_s with recall >= kResumeFraction * before
  static constexpr double kResumeFraction = 0.9;
};

class OutageMonitor {
 public:
  // outages[c]: camera c's windows; tolerance_voxels as the evaluation's.
  OutageMonitor(std::vector<std::vector<OutageWindow>> outages, int tolerance_voxels);
  bool empty() const { return outages_.empty(); }  // no camera has a window: every call does nothing

  // keys: the voxels camera `camera` saw in this frame; those truth contains are recorded. marking_points: the
  // frame's points to mark.
  void observe(std::size_t camera, double time_s, const std::vector<VoxelKey>& keys, const Truth& truth,
               std::size_t marking_points);
  // Before the update at time_s: an outage whose window has begun watches the voxels in map only its camera saw.
  void before_update(double time_s, const mapping::VoxelMap& map);
  // After the update at time_s: counts the watched voxels that left map unseen by the other cameras, until to_s.
  void after_update(double time_s, const mapping::VoxelMap& map);
  // One result per window (cameras in order), with the recall figures from the evaluation's snapshots.
  std::vector<OutageResult> results(const std::vector<EvaluationSnapshot>& snapshots) const;

 private:
  struct Active {
    OutageResult result;
    bool started = false, ended = false;
    std::vector<VoxelKey> watched;  // only-seen voxels still in the map and seen by no other camera
  };
  std::vector<Active> outages_;
  int tolerance_voxels_;
  std::unordered_map<VoxelKey, std::uint64_t, VoxelKeyHash> seen_by_;  // truth voxel -> bit per camera (< 64)
};

}  // namespace stvl::evaluation

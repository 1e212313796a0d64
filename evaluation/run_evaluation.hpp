#pragma once
// The evaluation's side of a run, frame by frame, in one object: the Evaluator (map against truth), the
// OutageMonitor (cameras that stop) and, at the end, the scenario's checks. The run loop calls
//   before_update(frame, world, map)          with the frame sensed and the map before the layer's update;
//   after_update(frame, report, world, map)   once the layer's update (report) is in the map;
//   finish(end, world, map)            once, after the last frame: every figure and every check.
#include <string>
#include <vector>

#include "evaluation/checks.hpp"
#include "evaluation/evaluator.hpp"
#include "evaluation/map_view.hpp"
#include "evaluation/outage.hpp"
#include "evaluation/soak.hpp"
#include "layer/layer.hpp"
#include "pipeline/config.hpp"
#include "pipeline/frame.hpp"

namespace stvl::evaluation {

// How the run ended, as the run loop saw it.
struct RunEnd {
  std::size_t frames = 0;  // frames taken
  double time_s = 0;       // simulated time of the last frame
  bool fell = false;       // the robot fell over or left the world at fell_at_s, tilted by tilt_rad
  double fell_at_s = 0, tilt_rad = 0;
  bool path_required = false;  // the scenario stops at the path's end (and so must reach it)
  bool path_done = false;
  double duration_s = 0;        // the scenario's duration
  double cut_short_from_s = 0;  // > 0: --duration shortened the run from this many seconds
  bool path_required_when_cut_short = false;
  std::string blocked;  // blocked_diagnosis() when the robot stopped short of the path's end
  SoakSeries soak;
};

// Everything the evaluation concluded.
struct RunVerdict {
  EvaluationSummary evaluation;  // empty when no frame was taken
  TopDown top_down;
  PhaseTimes phases;  // wall-clock totals per phase (profiling only)
  MapView map_view;
  std::vector<OutageResult> outages;
  // robot_upright, path_completed (when required), then evaluation, outage and soak checks (frames > 0).
  std::vector<CheckResult> checks;
};

class RunEvaluation {
 public:
  // cameras: the run's cameras, by index (names, intrinsics, marking ranges, outages). Throws
  // std::invalid_argument for a bad config.
  RunEvaluation(const sim::World& world, const EvaluationConfig& config, const ChecksConfig& checks,
                const std::vector<pipeline::CameraConfig>& cameras);

  // Before the frame's map update, with the map as the frame before left it (clearing latency, outages).
  void before_update(const pipeline::Frame& frame, const sim::World& world, const mapping::VoxelMap& map);
  // After the update: the robot's pose, what the update cleared, what the noise-free camera saw, the outages,
  // and a snapshot when one is due (every evaluate_every_s).
  void after_update(const pipeline::Frame& frame, const layer::UpdateReport& report, const sim::World& world,
                    const mapping::VoxelMap& map);
  // A frame lost on the way to the layer (camera timing's drops, the tf filter's), at time_s: what its noise-free
  // camera saw goes into recall's denominator (the truth the camera looked at and the map never got).
  void observe_lost(const pipeline::Frame& frame, double time_s, const sim::World& world);
  // Wall-clock milliseconds of the last frame's before_update() and after_update() together.
  double last_frame_ms() const { return frame_ms_; }

  // The final snapshot, summary, map view and every check; `map` is the final map.
  RunVerdict finish(const RunEnd& end, const sim::World& world, const mapping::VoxelMap& map);

  // The layer's own costmap for the 2D scores (Evaluator::set_layer_costmap): nav2's layers.
  void set_layer_costmap(std::function<mapping::Costmap2D()> costmap) {
    evaluator_.set_layer_costmap(std::move(costmap));
  }
  // The Evaluator's ground truth, at the world's state of the last update.
  const Truth& truth() const { return evaluator_.truth(); }
  // Another costmap's lethal cells (nav2's master) against that truth's footprint, with the evaluation's
  // tolerance and phantom rules (lethal_against_truth()).
  LethalVsTruth against_truth(const mapping::Costmap2D& costmap) const;

 private:
  CameraView view_of(const pipeline::Frame& frame) const;

  EvaluationConfig config_;
  ChecksConfig checks_;
  std::vector<std::string> camera_names_;
  std::vector<sensors::CameraIntrinsics> intrinsics_;
  std::vector<double> marking_range_m_;  // per camera: the farthest any of its marking sources marks
  Evaluator evaluator_;
  OutageMonitor outages_;
  double next_evaluation_s_;
  double before_ms_ = 0, frame_ms_ = 0;
};

}  // namespace stvl::evaluation

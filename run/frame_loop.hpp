#pragma once
// The one frame loop of `run` and `replay`: frames come from a FrameSource (simulated: the Pipeline; recorded: a
// bag or folder through the same sensing), and each goes down the floors once:
//
//   sense (source.next) -> hooks.before_update -> layer.update -> hooks.after_update -> outputs (bag, series)
//
// The stop rules (the source's end, a stop request, a robot that fell, the hooks' done()), the per-frame series,
// the real-time factor, the bag with its final map and the map files exist here once.
#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "layer/layer.hpp"
#include "pipeline/config.hpp"
#include "pipeline/frame.hpp"
#include "run/bag_recorder.hpp"
#include "run/frame_outputs.hpp"

namespace stvl::run {

// Where frames come from.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // The next frame, sensed up to its observation (owned by the source, valid until the next call); null when there
  // is none. Throws std::invalid_argument for a frame that cannot be taken (a recording's bad frame).
  virtual const pipeline::Frame* next() = 0;
  // The cameras the frames come from (index = Frame::camera_index).
  virtual const std::vector<pipeline::CameraConfig>& cameras() const = 0;
  // The bag for these frames: before the first frame (first null), or, when the source needs a frame to know its
  // cameras' poses, at the first one. Null when it cannot open it yet.
  virtual std::unique_ptr<BagRecorder> open_bag(const std::string& path, const BagSettings& settings,
                                                const pipeline::Frame* first) = 0;
};

// What runs beside the layer each frame: the evaluation (a run's truth), samples, progress.
class FrameHooks {
 public:
  virtual ~FrameHooks() = default;
  // With the frame sensed and the layer as the frames before left it.
  virtual void before_update(const pipeline::Frame&, const layer::Layer&) {}
  // Once the layer took the frame's observation.
  virtual void after_update(const pipeline::Frame&, const layer::UpdateReport&, const layer::Layer&) {}
  // Just before the frame's messages go into the bag: messages of the hooks' own (a closed loop's /cmd_vel, /plan,
  // costmaps), each stamped at or before the frame.
  virtual void before_bag(BagRecorder&, const pipeline::Frame&) {}
  // Wall-clock milliseconds the hooks spent on the last frame (the series' evaluation stage).
  virtual double last_frame_ms() const { return 0.0; }
  // After the frame's outputs, with the frames taken so far: whether the loop ends here.
  virtual bool done(const pipeline::Frame&, const layer::UpdateReport&, std::size_t /*frames*/) { return false; }
};

struct FrameLoopSettings {
  std::string bag_path;  // empty: no bag
  BagSettings bag;
  double publish_period_s = 1.0;  // the bag's map and costmap (MapPublishClock)
  MapPublishClock::Grid publish_grid = MapPublishClock::Grid::kFixed;
  // A run publishes the map only at a frame that updated it; a replay at every frame due.
  bool publish_after_updates_only = true;
  const std::atomic<bool>* stop_requested = nullptr;
};

// What a run and a replay both record over their frames.
struct FrameLoopResult {
  StageSeries times;
  std::vector<StageSeries> camera_times;                             // per camera index: its frames' render .. mark
  std::vector<Eigen::Vector2d> path_W;                               // base_link at each frame
  std::vector<std::size_t> points_raw, points_filtered, map_voxels;  // per frame
  std::size_t frames = 0;
  std::size_t footprint_voxels_cleared = 0;  // map.clear_footprint_voxels_below, summed over the updates
  double sim_time_s = 0;                     // the last frame's stamp (simulated or recorded)
  double wall_time_s = 0;
  double real_time_factor = 0;  // simulated (or recorded) seconds per wall-clock second
  bool interrupted = false;
  bool fell = false;  // the last frame's robot had fallen over or left the world (at fell_at_s)
  double fell_at_s = 0;
  std::vector<layer::SourceStatus> sources;  // at the end
};

// Runs frames from `source` through `layer` until one of the stop rules; the bag (settings.bag_path) ends with
// the final map, and stays as <bag>.active when interrupted. Returns the series and how the loop ended.
FrameLoopResult run_frame_loop(FrameSource& source, layer::Layer& layer, FrameHooks& hooks,
                               const FrameLoopSettings& settings);

// map.vdb, map.ply (deterministic bytes: a .vdb file carries a random UUID), costmap.pgm/.yaml when the map is not
// empty, and nav2_costmap.pgm/.yaml when the layer feeds a master costmap, into out_dir.
void write_layer_outputs(const layer::Layer& layer, const std::string& out_dir);

}  // namespace stvl::run

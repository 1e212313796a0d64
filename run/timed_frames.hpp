#pragma once
// Time as a failure (issue 43): the simulated frames as a robot's subscriber gets them. Each camera's frames arrive
// after their latency, carry the stamp their driver writes, and some are lost (sensors/camera_timing.hpp); each
// reading then waits in the layer's tf message filter for the robot's pose at its stamp, or is dropped
// (layer/tf_filter.hpp). The layer gets the readings in delivery order at their delivery time (its clock: decay,
// update ticks, staleness), their clouds placed with the pose tf gives at the stamp: a stamp off the capture time
// on a moving robot smears every surface.
//
//   SimulatedFrames -> TimedFrames -> frame loop -> layer
//
// With localization (sim/localization.hpp) the pose at the stamp is the localizer's: the map -> odom correction
// in force at the stamp composed with odometry at the stamp; a layer in odom (localization.global_frame: odom, the
// local costmap's frame) is not moved by the corrections and is judged as placed with the truth (odometry's drift
// between a reading and the evaluation is not counted).
//
// The simulator runs on to each odometry message's time to record the poses tf interpolates (whole
// timesteps, so the run's physics is that of an untimed run).
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "pipeline/pipeline.hpp"
#include "run/frame_loop.hpp"

namespace stvl::run {

// What the timing did to one camera's frames over a run.
struct CameraTimingStats {
  std::size_t captured = 0, delivered = 0;
  std::map<std::string, std::size_t> dropped;            // by reason: camera, tf_timeout, queue_full
  double mean_delay_s = 0, max_delay_s = 0;              // capture to delivery, of those delivered
  double mean_stamp_error_s = 0, max_stamp_error_s = 0;  // |stamp - capture|, of those delivered
  std::size_t after_end = 0;  // delivered after the run's end (not dropped: the run stopped first)
};

// What localization did over a run (all zero without it).
struct LocalizationStats {
  std::size_t corrections = 0;  // map -> odom corrections published
  std::size_t jumps = 0;        // scripted jumps that took effect
  // How far the localizer's map pose at the stamp of each delivered reading was from the truth (the error every
  // reading was placed with in a map-frame layer).
  double mean_error_m = 0, max_error_m = 0, mean_error_yaw_rad = 0, max_error_yaw_rad = 0;
  std::size_t readings = 0;
};

// One captured frame's fate, for the report's timeline.
struct TimedFrameEvent {
  std::size_t camera_index = 0;
  double capture_s = 0;
  double delivered_s = -1;  // -1: not delivered
  std::string reason;       // "delivered", "camera", "tf_timeout", "queue_full", "after_end"
};

class TimedFrames : public FrameSource {
 public:
  // inner: the pipeline's frames (SimulatedFrames, which ends at duration_s); seed: the scenario's (each camera's
  // draws derive from it and the camera's index). map_copy (closed loop with localization): each frame's observation
  // is the local costmap's, in odom, and observation_map a copy placed in map for the global costmap's layer.
  TimedFrames(FrameSource& inner, pipeline::Pipeline& pipeline, std::uint64_t seed, double duration_s,
              bool map_copy = false);
  const pipeline::Frame* next() override;
  const std::vector<pipeline::CameraConfig>& cameras() const override { return inner_.cameras(); }
  std::unique_ptr<BagRecorder> open_bag(const std::string& path, const BagSettings& settings,
                                        const pipeline::Frame* first) override {
    return inner_.open_bag(path, settings, first);
  }
  // Per camera, in camera order.
  const std::vector<CameraTimingStats>& stats() const { return stats_; }
  // Every captured frame's fate in the order it was settled (frames still in flight at the end are not listed).
  const std::vector<TimedFrameEvent>& events() const { return events_; }
  // What localization did (the corrections are the simulator's: sim::Simulator::corrections()).
  LocalizationStats localization() const;
  // Called with every frame lost on the way (camera, tf_timeout, queue_full; not after_end) when its loss is known,
  // at the capture time being processed then (never earlier than a frame already handed on): the evaluation counts
  // what the lost frame's camera saw in recall's denominator, as the camera looked there.
  using LostFrameObserver = std::function<void(const pipeline::Frame& frame, double time_s)>;
  void set_lost_observer(LostFrameObserver observer) { lost_observer_ = std::move(observer); }

 private:
  struct Pending {
    pipeline::Frame frame;  // a copy: the pipeline overwrites its own at the next step
    double capture_s = 0, stamp_s = 0, delivered_s = 0;
    std::uint64_t order = 0;
  };
  // Records the robot's pose and odometry at every odometry message time up to time_s (running the simulator there).
  void record_poses_until(double time_s);
  // The robot's pose (truth, or odometry) tf gives at stamp_s (interpolated between the messages around it).
  Eigen::Isometry3d pose_at(Eigen::Isometry3d pipeline::OdomMessage::*pose, double stamp_s) const;
  // The next captured frame's timing: kept pending (in delivery order) or counted as dropped. False at the end.
  bool capture();
  void deliver(Pending& p);

  FrameSource& inner_;
  pipeline::Pipeline& pipeline_;
  std::uint64_t seed_;
  double duration_s_;
  bool map_copy_;
  const layer::TfTimingConfig tf_;
  std::vector<CameraTimingStats> stats_;
  std::vector<TimedFrameEvent> events_;
  std::vector<Pending> pending_;                 // ordered by delivery time, then capture order
  std::vector<std::deque<double>> queued_;       // per camera: delivery times of its readings waiting in the filter
  std::vector<pipeline::OdomMessage> messages_;  // odometry message k (time k / rate): poses tf gives, the bag's
  std::size_t messages_sent_ = 0;                // handed on with a frame so far
  LocalizationStats localization_;
  std::uint64_t order_ = 0;
  bool inner_done_ = false;
  pipeline::Frame out_;
  const pipeline::Frame* passthrough_ = nullptr;  // a frame of a fallen robot: handed on as it is
  LostFrameObserver lost_observer_;
  void lost(const pipeline::Frame& frame, double time_s) {
    if (lost_observer_) lost_observer_(frame, time_s);
  }
};

}  // namespace stvl::run

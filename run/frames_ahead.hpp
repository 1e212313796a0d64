#pragma once
// A pipeline's frames made ahead of the frame loop on two threads of their own: while the loop updates the layer
// with frame k and evaluates it (on the world's snapshot at k), frame k + 1 is sensed (noise, cloud, decimation)
// on one thread and frame k + 2 captured (physics, render) on the other. The frames and their order are those of
// Pipeline::step() one after another: capture() runs in frame order on one thread, sense() in frame order on the
// other, each frame sensed after its capture. Only where nothing the loop does reaches the simulator between
// frames (not in closed loop, not with camera timing).
#include <deque>
#include <future>

#include "common/serial_worker.hpp"
#include "pipeline/pipeline.hpp"

namespace stvl::run {

class FramesAhead {
 public:
  // Takes over `pipeline` (its world snapshots on, its GL contexts moved to the capturing thread) up to duration_s.
  FramesAhead(pipeline::Pipeline& pipeline, double duration_s);
  // Waits for the frames in flight and releases the GL contexts on the capturing thread.
  ~FramesAhead();
  FramesAhead(const FramesAhead&) = delete;
  FramesAhead& operator=(const FramesAhead&) = delete;

  // The next frame, valid until the next call; null past duration_s and after a frame whose robot fell (that
  // frame is given, and the simulator stops there). Rethrows the error of the frame's capture or sensing.
  const pipeline::Frame* next();

 private:
  void submit();  // the next frame's capture, then its sensing
  pipeline::Pipeline& pipeline_;
  double duration_s_;
  bool stopped_ = false;  // capturing thread only: past the duration, a fallen robot or an error
  std::deque<std::future<const pipeline::Frame*>> in_flight_;
  SerialWorker capture_, sense_;  // last: they start after the members their tasks use
};

}  // namespace stvl::run

#pragma once
// One drive for several runs ("twins": the same scenario under different layer, filter or evaluation settings):
// the simulator, the renders and the camera noise are made once per frame, on a thread of their own, and every twin
// takes each frame in turn and senses it with its own settings (edge filter, cloud, decimation). A twin's frames are
// those its own run would make, so its outputs are its own run's (tests/run/test_shared_drive.cpp); the drive runs
// one frame ahead of the slowest twin.
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/pipeline.hpp"

namespace stvl::run {

// Why `sets` (KEY=VALUE, as run --set takes them) cannot be a twin's own: the first key that may change the drive
// (anything but map., filter., evaluation., checks., outputs., name and a camera's edge_filter.), or a malformed
// assignment; empty when every key only changes what is done with the frames.
std::string twin_sets_problem(const std::vector<std::string>& sets);

// One twin as run --twin and sweep --twin take it: "OUT;KEY=VALUE;...", its output folder and its own --sets.
struct TwinSpec {
  std::string out_dir;
  std::vector<std::string> sets;
};
// Throws std::invalid_argument naming the text for an empty folder or a set that twin_sets_problem refuses.
TwinSpec parse_twin(const std::string& text);

class SharedDrive {
 public:
  // Takes over `pipeline` (world snapshots on, its GL contexts moved to the drive's thread) for `twins` twins, up to
  // duration_s; starts the drive's thread.
  SharedDrive(pipeline::Pipeline& pipeline, std::size_t twins, double duration_s);
  // Stops the drive's thread (stop()) and waits for it; the thread releases the GL contexts as it ends.
  ~SharedDrive();
  SharedDrive(const SharedDrive&) = delete;
  SharedDrive& operator=(const SharedDrive&) = delete;

  // Twin `twin`'s next frame, captured and with its noise, copied into `into` (everything up to its depth image;
  // into's cloud buffers are kept): false past duration_s or after a frame whose robot fell. The frame's world (its
  // snapshot) stays valid until this twin's next take() or leave(). Rethrows the drive's error.
  bool take(std::size_t twin, pipeline::Frame& into);
  // Twin `twin` takes no more frames: the drive goes on without waiting for it.
  void leave(std::size_t twin);
  // No more frames for anyone (a twin failed): every take() from now on gives false.
  void stop();

 private:
  void drive();           // the drive's thread
  bool all_took() const;  // every twin that has not left took the latest frame (lock held)
  pipeline::Pipeline& pipeline_;
  double duration_s_;
  std::mutex mutex_;
  std::condition_variable changed_;
  const pipeline::Frame* latest_ = nullptr;  // the frame number `captured_ - 1`
  std::size_t captured_ = 0;
  std::vector<std::size_t> taken_;  // per twin: frames taken
  std::vector<bool> left_;
  bool ended_ = false, stop_ = false;
  std::exception_ptr error_;
  std::thread thread_;  // last: starts once the members it uses are made
};

}  // namespace stvl::run

#pragma once
// What a run and a replay share around their frame loops: the options, the per-stage time series, the progress
// line, the sampled depth frames for the report, and when the map goes into the bag.
#include <atomic>
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "layer/layer.hpp"
#include "pipeline/frame.hpp"
#include "sensors/depth_image.hpp"

namespace stvl::run {

struct RunOptions {
  std::string out_dir;                                // empty: no files
  std::string bag_path;                               // empty: no bag
  std::string bag_format;                             // "ros1", "ros2", or empty: by bag_path (.mcap -> ros2)
  std::string bag_compression;                        // empty: none for ROS 1, zstd for ROS 2
  std::string bag_topics;                             // empty: all for ROS 1, default for ROS 2 (recording::BagTopics)
  bool progress = true;                               // progress bar on a TTY, plain lines otherwise
  const std::atomic<bool>* stop_requested = nullptr;  // set from a signal handler
  // > 0: --duration cut the run short from the scenario's own duration (seconds); a path not reached is then
  // reported as not evaluated unless require_path (--require-path).
  double cut_short_from_s = 0;
  bool require_path = false;
  // Frames k + 1 and k + 2 made on two threads of their own while frame k updates the layer and is evaluated
  // (run/frames_ahead.hpp; same outputs; off: one after another, --no-run-ahead). Never in closed loop or with camera
  // timing, which drive or read the live simulator between frames.
  bool run_ahead = true;
};

// Throws std::invalid_argument naming both paths when the bag at bag_path (format "ros1", "ros2" or "" as in
// RunOptions) would take the place of the output folder out_dir or of a folder above it: a ROS 1 bag's file, a
// rosbag2 folder (FILE.mcap -> folder FILE) or either's <path>.active being out_dir or holding it. The outputs
// would replace the bag, or the bag the outputs. A bag inside out_dir is fine (a run moves it with the outputs).
// Paths are compared resolved (std::filesystem::weakly_canonical); nothing is done when either is empty.
void check_bag_outside_outputs(const std::string& out_dir, const std::string& bag_path, const std::string& bag_format);

// Wall-clock milliseconds per frame, one series per stage (a frame's sensing and the layer's update, plus what
// the loop adds); timings are the only part of a run that is not deterministic.
struct StageSeries {
  std::vector<double> render, noise, cloud, filter, clear, mark, evaluation, bag, frame;
  // One frame's sensing (render .. filter) and the layer's update (clear, mark).
  void append(const pipeline::SensingTimes& sensing, const layer::UpdateReport& update);
};

// A progress bar on a terminal, a line per 10 % otherwise; nothing when disabled.
class Progress {
 public:
  Progress(bool enabled, double duration_s);
  void update(double t_s, std::size_t frame);
  void done();

 private:
  bool enabled_, tty_;
  double duration_s_;
  int next_percent_ = 0;
};

// A depth frame for the report: <frames_dir>/<prefix>depth_NNNNN.png (16-bit mm) and ..._color.png (near blue to
// far red over min_range_m .. 6 m), each written atomically.
void write_sample_depth_frame(const std::filesystem::path& frames_dir, const std::string& prefix,
                              std::size_t frame_index, const sensors::DepthImage& depth, double min_range_m);

// `count` depth frames of one camera saved evenly over a run of duration_s at rate_hz (none without a folder).
class FrameSampler {
 public:
  FrameSampler(const std::filesystem::path& frames_dir, int count, double duration_s, double rate_hz,
               std::string prefix);
  void offer(const pipeline::Frame& frame, double min_range_m) const;

 private:
  std::filesystem::path dir_;
  std::string prefix_;
  std::size_t every_ = 0;
};

// When the map and costmap go into the bag: at the first frame at or after each publish time. A run's publish
// times lie on a fixed grid (k * period_s); a replay's follow the recorded stamps (period_s after the last
// publish), which jitter.
class MapPublishClock {
 public:
  enum class Grid { kFixed, kAfterLast };
  MapPublishClock(double period_s, Grid grid) : period_s_(period_s), grid_(grid) {}
  // Whether the frame at time_s publishes (and, if so, the clock moves on).
  bool due(double time_s);
  // Whether the map at end_time_s still needs publishing (the bag must end with the final map).
  bool final_due(double end_time_s) const { return last_s_ != end_time_s; }

 private:
  double period_s_;
  Grid grid_;
  double next_s_ = 0.0, last_s_ = -1.0;
};

}  // namespace stvl::run

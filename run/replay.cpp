#include "run/replay.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <set>
#include <stdexcept>

#include "common/atomic_file.hpp"
#include "common/units.hpp"
#include "layer/layer.hpp"
#include "pipeline/sensing.hpp"

namespace stvl::run {
namespace {

bool same_model(const sensors::CameraIntrinsics& a, const sensors::CameraIntrinsics& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy && a.cx == b.cx && a.cy == b.cy;
}

// The scenario's camera with the recording's intrinsics; its sources' FOV follows where it was the camera's.
pipeline::PipelineConfig replay_config(const ReplaySettings& settings, const recording::RecordingInfo& info) {
  pipeline::PipelineConfig config = settings.pipeline;
  if (config.cameras.empty()) throw std::invalid_argument("replay: the scenario has no camera");
  pipeline::CameraConfig camera = config.cameras.front();
  const double old_hfov = camera.intrinsics.hfov_rad(), old_vfov = camera.intrinsics.vfov_rad();
  camera.name = settings.camera_name;
  camera.intrinsics = info.intrinsics;
  if (info.frame_count > 1 && info.end_time_s > info.start_time_s)
    camera.intrinsics.rate_hz = double(info.frame_count - 1) / (info.end_time_s - info.start_time_s);
  camera.outages.clear();
  for (auto& source : camera.sources) {
    if (std::abs(source.params.horizontal_fov_rad - old_hfov) < kAngleEpsilon_rad)
      source.params.horizontal_fov_rad = camera.intrinsics.hfov_rad();
    if (std::abs(source.params.vertical_fov_rad - old_vfov) < kAngleEpsilon_rad)
      source.params.vertical_fov_rad = camera.intrinsics.vfov_rad();
  }
  config.cameras = {camera};
  config.robot_geoms_seen.clear();
  pipeline::validate_cameras(config);
  return config;
}

// Indices of `count` frames spread evenly over `total` (fewer when there are fewer frames).
std::set<std::size_t> sample_indices(std::size_t total, int count) {
  std::set<std::size_t> out;
  for (int i = 0; i < count && total > 0; ++i)
    out.insert(std::min(total - 1, static_cast<std::size_t>((i + 0.5) * double(total) / count)));
  return out;
}

// A recording's frames, checked (one camera model, stamps in order) and sensed; the bag opened at the first frame,
// whose poses give base_link -> camera.
class RecordedFrames : public FrameSource {
 public:
  RecordedFrames(recording::Recording& recording, const pipeline::PipelineConfig& config, std::size_t total)
      : recording_(recording), config_(config), sensing_(config), total_(total) {
    f_.camera_index = 0;
    f_.camera = config.cameras.front().name;
  }
  const pipeline::Frame* next() override {
    if (taken_ >= total_ || !recording_.next(frame_)) return nullptr;
    const std::string& path = recording_.info().path;
    if (!same_model(frame_.intrinsics, config_.cameras.front().intrinsics))
      throw std::invalid_argument(path + ": frame " + std::to_string(frame_.index) +
                                  ": its camera model differs from the first frame's; a replay takes one camera model");
    // Frames recorded as a subscriber got them may be stamped a little out of order (latency with jitter, issue
    // 43): such a frame is placed with the pose at its stamp and taken at the layer's time so far (its clock does
    // not run back). More than kMaxStampReorder_s back is a broken recording.
    double time_s = frame_.time_s;
    if (taken_ > 0 && frame_.time_s < f_.time_s) {
      if (f_.time_s - frame_.time_s > kMaxStampReorder_s)
        throw std::invalid_argument(path + ": frame " + std::to_string(frame_.index) + " is stamped " +
                                    std::to_string(f_.time_s - frame_.time_s) + " s before the frame before it");
      if (out_of_order_++ == 0)
        std::fprintf(stderr,
                     "replay: frame %zu is stamped %.6f s before the frame before it (recorded as it arrived): "
                     "placed at its stamp, taken at the layer's time\n",
                     frame_.index, f_.time_s - frame_.time_s);
      time_s = f_.time_s;
    }
    ++taken_;
    f_.frame_index = frame_.index;
    f_.time_s = time_s;
    f_.stamp_s = frame_.time_s;
    f_.T_world_camera = frame_.T_fixed_camera;
    f_.T_world_base = frame_.T_fixed_base;
    f_.T_odom_base = frame_.T_fixed_base;
    f_.T_map_odom = Eigen::Isometry3d::Identity();
    std::swap(f_.depth, frame_.depth);
    f_.times = {};
    sensing_.sense(f_);
    f_.cameras_now = {{f_.T_world_camera, std::numeric_limits<double>::infinity()}};
    return &f_;
  }
  const std::vector<pipeline::CameraConfig>& cameras() const override { return config_.cameras; }
  std::unique_ptr<BagRecorder> open_bag(const std::string& path, const BagSettings& settings,
                                        const pipeline::Frame* first) override {
    if (!first) return nullptr;
    // The camera's optical frame on base_link; camera_link is the optical frame turned back.
    const Eigen::Isometry3d T_link_optical = sim::DiffDriveRobot::T_camera_link_optical();
    const Eigen::Isometry3d T_base_optical = first->T_world_base.inverse() * first->T_world_camera;
    return std::make_unique<BagRecorder>(
        path, settings,
        std::vector<BagSink::CameraFrames>{{first->camera, T_base_optical * T_link_optical.inverse(), T_link_optical}},
        nullptr);
  }
  const char* filter_device() const { return sensing_.filter_device(); }

 private:
  recording::Recording& recording_;
  const pipeline::PipelineConfig& config_;
  pipeline::Sensing sensing_;
  std::size_t total_, taken_ = 0, out_of_order_ = 0;
  static constexpr double kMaxStampReorder_s = 1.0;
  recording::RecordedFrame frame_;
  pipeline::Frame f_;
};

// The replay's side of each frame: the valid pixels, the sampled depth frames, a progress line every 100 frames.
class ReplayHooks : public FrameHooks {
 public:
  ReplayHooks(ReplayResult& r, const RunOptions& options, std::set<std::size_t> samples, std::size_t total)
      : r_(r), options_(options), samples_(std::move(samples)), total_(total) {}
  void after_update(const pipeline::Frame& f, const layer::UpdateReport&, const layer::Layer&) override {
    r_.valid_fraction.push_back(double(f.depth.valid_count()) /
                                double(std::max<std::size_t>(1, f.depth.depth_m.size())));
    if (samples_.count(r_.valid_fraction.size() - 1)) {
      write_sample_depth_frame(std::filesystem::path(options_.out_dir) / "frames", "", f.frame_index, f.depth,
                               r_.pipeline.cameras.front().intrinsics.min_range_m);
      r_.sampled_frames.push_back(f.frame_index);
    }
  }
  bool done(const pipeline::Frame& f, const layer::UpdateReport&, std::size_t frames) override {
    if (options_.progress && (frames % 100 == 0 || frames == total_))
      std::printf("replay: frame %zu of %zu, t=%.2f s\n", frames, total_, f.time_s);
    return false;
  }

 private:
  ReplayResult& r_;
  const RunOptions& options_;
  std::set<std::size_t> samples_;
  std::size_t total_;
};

}  // namespace

ReplayResult replay_recording(recording::Recording& recording, const ReplaySettings& settings,
                              const RunOptions& options) {
  check_bag_outside_outputs(options.out_dir, options.bag_path, options.bag_format);  // before anything is written
  ReplayResult r;
  r.recording = recording.info();
  r.pipeline = replay_config(settings, r.recording);
  const std::unique_ptr<layer::Layer> the_layer = layer::make_layer(pipeline::layer_config(r.pipeline));
  layer::Layer& layer = *the_layer;
  if (!options.out_dir.empty()) ensure_writable_directory(std::filesystem::path(options.out_dir) / "frames");
  const std::size_t total =
      settings.max_frames > 0 ? std::min(settings.max_frames, r.recording.frame_count) : r.recording.frame_count;
  FrameLoopSettings loop;
  loop.bag_path = options.bag_path;
  loop.bag = bag_settings(options.bag_path, options.bag_format, options.bag_compression, options.bag_topics);
  loop.publish_period_s = settings.publish_period_s;
  loop.publish_grid = MapPublishClock::Grid::kAfterLast;
  loop.publish_after_updates_only = false;
  loop.stop_requested = options.stop_requested;
  RecordedFrames frames(recording, r.pipeline, total);
  r.filter_device = frames.filter_device();
  ReplayHooks hooks(
      r, options,
      options.out_dir.empty() ? std::set<std::size_t>{} : sample_indices(total, settings.sample_depth_frames), total);
  static_cast<FrameLoopResult&>(r) = run_frame_loop(frames, layer, hooks, loop);
  if (r.interrupted) return r;
  if (r.frames == 0) throw std::invalid_argument(r.recording.path + ": no depth frame could be read");

  r.costmap = layer.costmap();
  for (std::uint8_t c : r.costmap.cells) r.lethal_cells += c == mapping::kCostLethal;
  r.final_voxels = layer.voxels().size();
  r.map_view = evaluation::make_map_view(layer.voxels());
  write_layer_outputs(layer, options.out_dir);
  return r;
}

}  // namespace stvl::run

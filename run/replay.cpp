#include "run/replay.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <set>
#include <stdexcept>

#include "common/stopwatch.hpp"
#include "common/atomic_file.hpp"
#include "pipeline/map_stages.hpp"
#include "run/bag_recorder.hpp"

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
    if (std::abs(source.params.horizontal_fov_rad - old_hfov) < 1e-9) source.params.horizontal_fov_rad = camera.intrinsics.hfov_rad();
    if (std::abs(source.params.vertical_fov_rad - old_vfov) < 1e-9) source.params.vertical_fov_rad = camera.intrinsics.vfov_rad();
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

}  // namespace

ReplayResult replay_recording(recording::Recording& recording, const ReplaySettings& settings, const RunOptions& options) {
  ReplayResult r;
  r.recording = recording.info();
  const std::string& recording_path = r.recording.path;
  r.pipeline = replay_config(settings, r.recording);
  const pipeline::CameraConfig& camera = r.pipeline.cameras.front();
  pipeline::MapStages stages(r.pipeline);
  r.filter_device = stages.filter_device();

  const std::filesystem::path out = options.out_dir;
  if (!options.out_dir.empty()) ensure_writable_directory(out / "frames");
  const std::size_t total = settings.max_frames > 0 ? std::min(settings.max_frames, r.recording.frame_count)
                                                    : r.recording.frame_count;
  const std::set<std::size_t> samples = options.out_dir.empty() ? std::set<std::size_t>{}
                                                                : sample_indices(total, settings.sample_depth_frames);
  const BagSettings bag_settings = run::bag_settings(options.bag_path, options.bag_format, options.bag_compression, options.bag_topics);
  std::unique_ptr<BagRecorder> bag;  // opened at the first frame, whose poses give base_link -> camera

  pipeline::FrameResult f;
  f.camera_index = 0;
  f.camera = camera.name;
  // STVL frees the footprint at the pose of the last update: the last frame's base.
  const BagRecorder::MapState map_state{&stages.map(), [&] {
    return stages.map().project_costmap(pipeline::costmap_options(r.pipeline, f.T_world_base));
  }};
  recording::RecordedFrame frame;
  const pipeline::MapStages::CamerasNow now{[&](std::size_t) { return f.T_world_camera; },
                                            [](std::size_t) { return std::numeric_limits<double>::infinity(); }};
  MapPublishClock publish(settings.publish_period_s, MapPublishClock::Grid::kAfterLast);
  const auto wall_start = SteadyClock::now();
  while (r.frames < total && recording.next(frame)) {
    if (options.stop_requested && options.stop_requested->load()) {
      r.interrupted = true;
      break;
    }
    const auto frame_start = SteadyClock::now();
    if (!same_model(frame.intrinsics, camera.intrinsics))
      throw std::invalid_argument(recording_path + ": frame " + std::to_string(frame.index) +
                                  ": its camera model differs from the first frame's; a replay takes one camera model");
    if (r.frames > 0 && frame.time_s < f.time_s)
      throw std::invalid_argument(recording_path + ": frame " + std::to_string(frame.index) + " is stamped " +
                                  std::to_string(f.time_s - frame.time_s) + " s before the frame before it");
    f.frame_index = frame.index;
    f.time_s = frame.time_s;
    f.T_world_camera = frame.T_fixed_camera;
    f.T_world_base = frame.T_fixed_base;
    f.T_odom_base = frame.T_fixed_base;
    f.T_map_odom = Eigen::Isometry3d::Identity();
    std::swap(f.depth, frame.depth);
    f.times = {};
    stages.sense(f);
    stages.update(f, now);

    r.times.cloud.push_back(f.times.cloud_ms);  // a recording has no render or noise stage
    r.times.filter.push_back(f.times.filter_ms);
    r.times.clear.push_back(f.times.clear_ms);
    r.times.mark.push_back(f.times.mark_ms);
    r.path_W.emplace_back(f.T_world_base.translation().head<2>());
    r.points_raw.push_back(static_cast<std::size_t>(f.point_count));
    r.points_filtered.push_back(static_cast<std::size_t>(f.marking_W.cols()));
    r.map_voxels.push_back(stages.map().size());
    r.valid_fraction.push_back(double(f.depth.valid_count()) / double(std::max<std::size_t>(1, f.depth.depth_m.size())));
    if (samples.count(r.frames)) {
      write_sample_depth_frame(out / "frames", "", f.frame_index, f.depth, camera.intrinsics.min_range_m);
      r.sampled_frames.push_back(f.frame_index);
    }
    const auto bag_start = SteadyClock::now();
    if (!options.bag_path.empty() && !bag) {
      // The camera's optical frame on base_link; camera_link is the optical frame turned back.
      const Eigen::Isometry3d T_link_optical = sim::DiffDriveRobot::T_camera_link_optical();
      const Eigen::Isometry3d T_base_optical = f.T_world_base.inverse() * f.T_world_camera;
      bag = std::make_unique<BagRecorder>(
          options.bag_path, bag_settings,
          std::vector<BagSink::CameraFrames>{{camera.name, T_base_optical * T_link_optical.inverse(), T_link_optical}},
          nullptr);
    }
    if (bag) bag->record(f, r.pipeline.cameras, map_state, publish.due(f.time_s));
    r.times.bag.push_back(ms_since(bag_start));
    r.times.frame.push_back(ms_since(frame_start));
    r.frames += 1;
    r.recorded_s = f.time_s;
    if (options.progress && (r.frames % 100 == 0 || r.frames == total))
      std::printf("replay: frame %zu of %zu, t=%.2f s\n", r.frames, total, f.time_s);
  }
  r.wall_time_s = s_since(wall_start);
  r.real_time_factor = r.wall_time_s > 0 ? r.recorded_s / r.wall_time_s : 0;
  if (r.interrupted) return r;
  if (r.frames == 0) throw std::invalid_argument(recording_path + ": no depth frame could be read");

  r.costmap = map_state.costmap();
  for (std::uint8_t c : r.costmap.cells) r.lethal_cells += c == mapping::kCostLethal;
  r.final_voxels = stages.map().size();
  r.map_view = evaluation::make_map_view(stages.map());
  r.sources = stages.source_status(r.recorded_s);
  if (bag) {
    if (publish.final_due(r.recorded_s)) bag->record_map(r.recorded_s, map_state);
    bag->close();
  }
  if (!options.out_dir.empty()) {
    stages.map().save_vdb((out / "map.vdb").string());
    stages.map().save_ply((out / "map.ply").string());
    if (!stages.map().empty()) mapping::write_costmap(r.costmap, (out / "costmap").string());
  }
  return r;
}

}  // namespace stvl::run

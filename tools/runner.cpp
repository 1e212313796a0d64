#include "tools/runner.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "common/stopwatch.hpp"
#include "common/atomic_file.hpp"
#include "common/splitmix.hpp"
#include "pipeline/pipeline.hpp"
#include "tools/bag_recorder.hpp"

namespace stvl::tools {
namespace {

class Progress {
 public:
  Progress(bool enabled, double duration_s) : enabled_(enabled), tty_(isatty(fileno(stdout))), duration_s_(duration_s) {}
  void update(double t_s, std::size_t frame) {
    if (!enabled_) return;
    const int percent = static_cast<int>(100.0 * std::min(1.0, t_s / duration_s_));
    if (tty_) {
      const int filled = percent / 4;
      std::printf("\r[%-25s] %3d%%  t=%6.2f s  frame %zu", std::string(filled, '#').c_str(), percent, t_s, frame);
      std::fflush(stdout);
    } else if (percent >= next_percent_) {
      std::printf("progress: %3d%%  t=%.2f s  frame %zu\n", percent, t_s, frame);
      next_percent_ = percent - percent % 10 + 10;
    }
  }
  void done() {
    if (enabled_ && tty_) std::printf("\n");
  }

 private:
  bool enabled_, tty_;
  double duration_s_;
  int next_percent_ = 0;
};

// Saves `count` depth frames evenly spread over the run (16-bit mm and colorized PNG) for the report.
// With several cameras the files are named <camera>_depth_NNNNN.
class FrameSampler {
 public:
  FrameSampler(const std::filesystem::path& frames_dir, int count, double duration_s, double rate_hz, std::string prefix)
      : dir_(frames_dir), prefix_(std::move(prefix)) {
    const std::size_t expected = static_cast<std::size_t>(duration_s / (1.0 / rate_hz)) + 1;
    every_ = count > 0 && !frames_dir.empty() ? std::max<std::size_t>(1, expected / (count + 1)) : 0;
  }
  void offer(const pipeline::FrameResult& f, double min_range_m) const {
    if (!every_ || f.frame_index == 0 || f.frame_index % every_ != 0) return;
    write_sample_depth_frame(dir_, prefix_, f.frame_index, f.depth, min_range_m);
  }

 private:
  std::filesystem::path dir_;
  std::string prefix_;
  std::size_t every_ = 0;
};

// The pipeline's stage times of one frame, appended to a run's (or a camera's) series.
void append_stages(StageTimes& series, const pipeline::StageTimes& frame) {
  series.render.push_back(frame.render_ms);
  series.noise.push_back(frame.noise_ms);
  series.cloud.push_back(frame.cloud_ms);
  series.filter.push_back(frame.filter_ms);
  series.clear.push_back(frame.clear_ms);
  series.mark.push_back(frame.mark_ms);
}

// The pipeline; a mount it rejects once the world is loaded is blamed on the scenario's line.
std::unique_ptr<pipeline::Pipeline> build_pipeline(const Scenario& s) {
  try {
    return std::make_unique<pipeline::Pipeline>(s.pipeline);
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    for (std::size_t i = 0; i < s.camera_mount_locations.size() && i < s.pipeline.cameras.size(); ++i)
      if (message.rfind("camera '" + s.pipeline.cameras[i].name + "': mounted", 0) == 0)
        throw std::invalid_argument(s.camera_mount_locations[i] + ": " + message);
    throw;
  }
}

// About max_points of `points`, chosen by a hash of their voxel keys (spread evenly over the map, unlike every
// k-th in key order, which leaves stripes) and the same in every run.
Eigen::Matrix3Xf thinned(const std::vector<VoxelKey>& keys, const std::vector<Eigen::Vector3f>& points, std::size_t max_points) {
  const std::uint64_t keep_per_1024 =
      points.size() <= max_points ? 1024 : std::max<std::uint64_t>(1, 1024 * max_points / points.size());
  std::vector<Eigen::Vector3f> kept;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (splitmix64_mix(VoxelKeyHash{}(keys[i])) % 1024 < keep_per_1024) kept.push_back(points[i]);
  Eigen::Matrix3Xf out(3, Eigen::Index(kept.size()));
  for (std::size_t c = 0; c < kept.size(); ++c) out.col(Eigen::Index(c)) = kept[c];
  return out;
}

}  // namespace

MapView make_map_view(const mapping::VoxelMap& map, const evaluation::Truth& truth, int tolerance_voxels,
                      std::size_t max_points) {
  MapView view;
  view.voxel_size_m = map.voxel_size_m();
  std::vector<Eigen::Vector3f> good, bad, truth_points;
  std::vector<VoxelKey> good_keys, bad_keys, truth_keys;
  for (const VoxelKey& key : map.voxel_keys()) {
    const bool near = truth.near(key, tolerance_voxels);
    (near ? good : bad).push_back(map.center_of(key).cast<float>());
    (near ? good_keys : bad_keys).push_back(key);
  }
  const Eigen::Matrix3Xf centers = truth.voxel_centers();
  for (Eigen::Index i = 0; i < centers.cols(); ++i) {
    truth_points.push_back(centers.col(i));
    truth_keys.push_back(voxel_key(centers.col(i).cast<double>(), view.voxel_size_m));
  }
  view.mapped_true = good.size(), view.mapped_false = bad.size(), view.truth = truth_points.size();
  view.mapped_true_W = thinned(good_keys, good, max_points);
  view.mapped_false_W = thinned(bad_keys, bad, max_points);
  view.truth_W = thinned(truth_keys, truth_points, max_points);
  return view;
}

void write_sample_depth_frame(const std::filesystem::path& frames_dir, const std::string& prefix, std::size_t frame_index,
                              const sensors::DepthImage& depth, double min_range_m) {
  char name[64];
  std::snprintf(name, sizeof name, "depth_%05zu", frame_index);
  const std::string base = prefix + name;
  sensors::write_depth_png_mm(depth, (frames_dir / (base + ".png")).string());
  sensors::write_depth_png_colorized(depth, (frames_dir / (base + "_color.png")).string(), min_range_m, 6.0);
}

MapView make_map_view(const mapping::VoxelMap& map, std::size_t max_points) {
  MapView view;
  view.voxel_size_m = map.voxel_size_m();
  std::vector<Eigen::Vector3f> points;
  const std::vector<VoxelKey> keys = map.voxel_keys();
  for (const VoxelKey& key : keys) points.push_back(map.center_of(key).cast<float>());
  view.unjudged = points.size();
  view.unjudged_W = thinned(keys, points, max_points);
  return view;
}

bool RunResult::passed() const {
  for (const auto& c : checks)
    if (!c.passed) return false;
  return !interrupted;
}

RunResult run_scenario(const Scenario& s, const RunOptions& options) {
  RunResult r;
  r.scenario = s;
  const std::filesystem::path out = options.out_dir;
  const std::unique_ptr<pipeline::Pipeline> owned = build_pipeline(s);
  pipeline::Pipeline& pipeline = *owned;
  evaluation::Evaluator evaluator(pipeline.simulator().world(), evaluation_config(s));
  std::vector<std::vector<evaluation::OutageWindow>> outage_windows;
  for (const auto& c : s.pipeline.cameras) {
    outage_windows.emplace_back();
    for (const auto& o : c.outages) outage_windows.back().push_back({o.from_s, o.to_s});
  }
  evaluation::OutageMonitor outages(std::move(outage_windows), s.evaluation.tolerance_voxels);
  if (!options.out_dir.empty()) ensure_writable_directory(out / "frames");
  r.gl_backend = pipeline.gl_backend();
  r.filter_device = pipeline.filter_device();
  std::unique_ptr<BagRecorder> bag;
  if (!options.bag_path.empty())
    bag = std::make_unique<BagRecorder>(options.bag_path, parse_bag_compression(options.bag_compression), pipeline,
                                        evaluator.truth().voxel_centers());
  std::vector<FrameSampler> samplers;
  const bool several = s.pipeline.cameras.size() > 1;
  for (const auto& c : s.pipeline.cameras)
    samplers.emplace_back(options.out_dir.empty() ? std::filesystem::path() : out / "frames",
                          s.outputs.sample_depth_frames, s.duration_s, c.intrinsics.rate_hz, several ? c.name + "_" : "");
  r.camera_times.resize(s.pipeline.cameras.size());

  double next_evaluation_s = s.evaluation.evaluate_every_s;
  double next_publish_s = 0.0, last_publish_s = -1.0;
  Progress progress(options.progress, s.duration_s);
  SoakSampler soak(s.outputs.soak_sample_every_s);
  const auto wall_start = SteadyClock::now();
  bool path_done = false;
  double evaluation_ms = 0.0;
  const auto view_of = [&](const pipeline::FrameResult& f) {
    const auto& c = s.pipeline.cameras[f.camera_index];
    double range_m = 0.0;  // the farthest any of its marking sources marks
    for (const auto& source : c.sources)
      if (source.params.marking) range_m = std::max(range_m, source.params.obstacle_range_m);
    return evaluation::CameraView{&f.clean_depth, c.intrinsics, f.T_world_camera, range_m, f.camera_index};
  };
  // The evaluation's look at the map before this frame's update (clearing latency).
  const auto before_map_update = [&](const pipeline::FrameResult& f, const mapping::VoxelMap& map) {
    const auto start = SteadyClock::now();
    evaluator.observe_clearing(f.time_s, pipeline.simulator().world(), view_of(f), map);
    outages.before_update(f.time_s, map);
    evaluation_ms = ms_since(start);
  };

  while (pipeline.next_time_s() <= s.duration_s + 1e-9) {
    if (options.stop_requested && options.stop_requested->load()) {
      r.interrupted = true;
      break;
    }
    evaluation_ms = 0.0;
    const pipeline::FrameResult& f = pipeline.step(before_map_update);
    if (!f.robot_upright) {
      r.checks.push_back(robot_upright_check(false, f.time_s, pipeline.simulator().robot().tilt_rad()));
      break;
    }
    r.path_W.emplace_back(f.T_world_base.translation().head<2>());
    append_stages(r.times, f.times);
    append_stages(r.camera_times[f.camera_index], f.times);

    auto start = SteadyClock::now();
    evaluator.set_robot_pose(f.T_world_base);
    evaluator.after_update(f.time_s, pipeline.map(), f.cleared_keys);
    evaluator.observe_hidden_clears(f.time_s, view_of(f), pipeline.map(), f.cleared_keys);
    evaluator.observe(f.time_s, view_of(f));
    outages.after_update(f.time_s, pipeline.map());
    outages.observe(f.camera_index, f.time_s, evaluator.frame_keys(), evaluator.truth(),
                    static_cast<std::size_t>(f.marking_W.cols()));
    if (f.time_s + 1e-9 >= next_evaluation_s) {
      evaluator.evaluate(f.time_s, pipeline.simulator().world(), pipeline.map());
      next_evaluation_s += s.evaluation.evaluate_every_s;
    }
    r.times.evaluation.push_back(evaluation_ms + ms_since(start));

    samplers[f.camera_index].offer(f, s.pipeline.cameras[f.camera_index].intrinsics.min_range_m);

    start = SteadyClock::now();
    if (bag) {
      const bool publish_map = f.time_s + 1e-9 >= next_publish_s;
      if (publish_map) next_publish_s += s.outputs.publish_period_s, last_publish_s = f.time_s;
      bag->record(f, pipeline, publish_map);
    }
    r.times.bag.push_back(ms_since(start));

    r.points_raw.push_back(static_cast<std::size_t>(f.point_count));
    r.points_filtered.push_back(static_cast<std::size_t>(f.marking_W.cols()));
    r.map_voxels.push_back(pipeline.map().size());
    soak.frame(f.time_s, f.times.clear_ms + f.times.mark_ms, f.times.map_cpu_ms, pipeline.simulator().follower().laps_completed(),
               pipeline.map());
    r.times.frame.push_back(f.times.render_ms + f.times.noise_ms + f.times.cloud_ms + f.times.filter_ms +
                            f.times.clear_ms + f.times.mark_ms + r.times.evaluation.back() + r.times.bag.back());
    r.frames += 1;
    r.footprint_voxels_cleared += f.footprint_cleared;
    r.sim_time_s = f.time_s;
    progress.update(f.time_s, r.frames);
    if (s.stop_at_path_end && pipeline.simulator().path_finished()) {
      path_done = true;
      break;
    }
  }
  progress.done();
  r.wall_time_s = std::chrono::duration<double>(SteadyClock::now() - wall_start).count();
  r.real_time_factor = r.wall_time_s > 0 ? r.sim_time_s / r.wall_time_s : 0;
  r.soak = soak.series();
  if (r.interrupted) return r;  // the bag stays as <bag>.active; no result file is written

  const bool fell = !r.checks.empty();
  if (!fell) r.checks.push_back(robot_upright_check(true, r.sim_time_s, 0.0));
  if (s.stop_at_path_end && !fell) r.checks.push_back(path_completed_check(path_done, r.sim_time_s, s.duration_s));
  if (r.frames > 0) {
    r.evaluation = evaluator.finish(r.sim_time_s, pipeline.simulator().world(), pipeline.map());
    r.top_down = evaluator.top_down();
    r.evaluation_phases = evaluator.phase_times();
    r.map_view = make_map_view(pipeline.map(), evaluator.truth(), s.evaluation.tolerance_voxels);
    r.outages = outages.results(r.evaluation.snapshots);
    std::vector<std::string> names;
    for (const auto& c : s.pipeline.cameras) names.push_back(c.name);
    for (auto& check : evaluation_checks(s.checks, r.evaluation, names)) r.checks.push_back(std::move(check));
    for (auto& check : outage_checks(s.checks, r.outages, names)) r.checks.push_back(std::move(check));

    for (auto& check : soak_checks(s.checks, r.soak)) r.checks.push_back(std::move(check));
  }
  r.sources = pipeline.source_status(r.sim_time_s);
  for (std::size_t c = 0; c < s.pipeline.cameras.size(); ++c) r.skipped_frames.push_back(pipeline.skipped_frames(c));
  if (bag) {
    // The bag ends with the final map, the one map.vdb and costmap.pgm hold.
    if (r.frames > 0 && last_publish_s != r.sim_time_s) bag->record_map(r.sim_time_s, pipeline);
    bag->close();
  }
  if (!options.out_dir.empty()) {
    pipeline.map().save_vdb((out / "map.vdb").string());
    pipeline.map().save_ply((out / "map.ply").string());  // deterministic bytes (a .vdb file carries a random UUID)
    if (!pipeline.map().empty()) mapping::write_costmap(pipeline.costmap(), (out / "costmap").string());
  }
  return r;
}

}  // namespace stvl::tools

#include "run/runner.hpp"

#include <cmath>
#include <filesystem>
#include <memory>
#include <thread>

#include "common/atomic_file.hpp"
#include "common/units.hpp"
#include "layer/layer.hpp"
#include "pipeline/pipeline.hpp"
#include "pipeline/sensing.hpp"
#include "run/closed_loop.hpp"
#include "run/frames_ahead.hpp"
#include "run/shared_drive.hpp"
#include "sim/contacts.hpp"

namespace stvl::run {
namespace {

// The pipeline; a mount it rejects once the world is loaded is blamed on the scenario's line.
std::unique_ptr<pipeline::Pipeline> build_pipeline(const config::Scenario& s) {
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

// A simulated run's bag: the cameras' mounts and the truth's voxels (latched).
std::unique_ptr<BagRecorder> bag_with_truth(const std::string& path, const BagSettings& settings,
                                            const std::vector<pipeline::CameraConfig>& cameras,
                                            const evaluation::Truth& truth) {
  const Eigen::Matrix3Xf truth_W = truth.voxel_centers();
  return std::make_unique<BagRecorder>(path, settings, camera_frames(cameras), &truth_W);
}

// The pipeline's frames up to the scenario's duration; the bag with the cameras' mounts and the truth. Running
// ahead (FramesAhead), the next frames are made on threads of their own while the loop takes this one.
class SimulatedFrames : public FrameSource {
 public:
  SimulatedFrames(pipeline::Pipeline& pipeline, double duration_s, const evaluation::Truth& truth)
      : pipeline_(pipeline), duration_s_(duration_s), truth_(truth) {}
  // Before the first next().
  void run_ahead() { ahead_ = std::make_unique<FramesAhead>(pipeline_, duration_s_); }
  // Once the loop has ended: the frames in flight are waited for and the threads end, so that nothing touches the
  // pipeline any more (it may have simulated up to two frames past the last one given).
  void stop() { ahead_.reset(); }
  // The last frame taken from the pipeline (its world: the live one, or its snapshot when running ahead); null
  // before the first.
  const pipeline::Frame* last() const { return last_; }
  const pipeline::Frame* next() override {
    const pipeline::Frame* f = nullptr;
    if (ahead_) f = ahead_->next();
    else if (pipeline_.next_time_s() <= duration_s_ + kTimeEpsilon_s) f = &pipeline_.step();
    if (f) last_ = f;
    return f;
  }
  const std::vector<pipeline::CameraConfig>& cameras() const override { return pipeline_.config().cameras; }
  std::unique_ptr<BagRecorder> open_bag(const std::string& path, const BagSettings& settings,
                                        const pipeline::Frame*) override {
    return bag_with_truth(path, settings, cameras(), truth_);
  }

 private:
  pipeline::Pipeline& pipeline_;
  double duration_s_;
  const evaluation::Truth& truth_;
  const pipeline::Frame* last_ = nullptr;
  std::unique_ptr<FramesAhead> ahead_;
};

// A twin's frames (run_twins): the shared drive's, each sensed with the twin's own settings.
class TwinFrames : public FrameSource {
 public:
  TwinFrames(SharedDrive& drive, std::size_t twin, const pipeline::PipelineConfig& config,
             const evaluation::Truth& truth)
      : drive_(drive), twin_(twin), config_(config), sensing_(config), truth_(truth) {}
  const pipeline::Frame* next() override {
    if (!drive_.take(twin_, frame_)) return nullptr;
    if (frame_.robot_upright) sensing_.sense(frame_);
    taken_ = true;
    return &frame_;
  }
  const pipeline::Frame* last() const { return taken_ ? &frame_ : nullptr; }  // its world: until drive.leave()
  const std::vector<pipeline::CameraConfig>& cameras() const override { return config_.cameras; }
  std::unique_ptr<BagRecorder> open_bag(const std::string& path, const BagSettings& settings,
                                        const pipeline::Frame*) override {
    return bag_with_truth(path, settings, cameras(), truth_);
  }
  const char* filter_device() const { return sensing_.filter_device(); }

 private:
  SharedDrive& drive_;
  std::size_t twin_;
  const pipeline::PipelineConfig& config_;
  pipeline::Sensing sensing_;
  const evaluation::Truth& truth_;
  pipeline::Frame frame_;
  bool taken_ = false;
};

// The run's side of each frame: the evaluation against the truth, sampled depth frames, the soak's samples, the
// progress line, where the robot last moved, and the stop at the path's end.
class RunHooks : public FrameHooks {
 public:
  RunHooks(const config::Scenario& s, const RunOptions& options, evaluation::RunEvaluation& evaluation,
           ClosedLoop* closed_loop)
      : s_(s),
        closed_loop_(closed_loop),
        evaluation_(evaluation),
        progress_(options.progress, s.duration_s),
        soak_(s.outputs.soak_sample_every_s) {
    const bool several = s.pipeline.cameras.size() > 1;
    const std::filesystem::path frames =
        options.out_dir.empty() ? std::filesystem::path() : std::filesystem::path(options.out_dir) / "frames";
    for (const auto& c : s.pipeline.cameras)
      samplers_.emplace_back(frames, s.outputs.sample_depth_frames, s.duration_s, c.intrinsics.rate_hz,
                             several ? c.name + "_" : "");
  }
  void before_update(const pipeline::Frame& f, const layer::Layer& layer) override {
    evaluation_.before_update(f, *f.world, layer.voxels());
  }
  void after_update(const pipeline::Frame& f, const layer::UpdateReport& report, const layer::Layer& layer) override {
    evaluation_.after_update(f, report, *f.world, layer.voxels());
    if (closed_loop_) closed_loop_->after_frame(f);
    samplers_[f.camera_index].offer(f, s_.pipeline.cameras[f.camera_index].intrinsics.min_range_m);
    const Eigen::Vector2d p_W = f.T_world_base.translation().head<2>();
    if (!((p_W - moved_at_W_).norm() <= 0.02)) moved_at_W_ = p_W, moved_s_ = f.time_s;
    soak_.frame(f.time_s, report.clear_ms + report.mark_ms, report.cpu_ms, f.laps_completed, layer.voxels());
  }
  double last_frame_ms() const override { return evaluation_.last_frame_ms(); }
  void before_bag(BagRecorder& bag, const pipeline::Frame& f) override {
    if (closed_loop_) closed_loop_->record_bag(bag, f.time_s);
  }
  bool done(const pipeline::Frame& f, const layer::UpdateReport& report, std::size_t frames) override {
    progress_.update(f.time_s, frames);
    path_done_ = s_.stop_at_path_end && report.map_updated() && f.path_finished;
    return path_done_ || (closed_loop_ && closed_loop_->finished());
  }
  // Once the loop has ended.
  void finish() { progress_.done(); }
  bool path_done() const { return path_done_; }
  double moved_s() const { return moved_s_; }  // when the robot last moved by more than 2 cm
  evaluation::SoakSeries soak() const { return soak_.series(); }

 private:
  const config::Scenario& s_;
  ClosedLoop* closed_loop_;
  evaluation::RunEvaluation& evaluation_;
  Progress progress_;
  evaluation::SoakSampler soak_;
  std::vector<FrameSampler> samplers_;
  Eigen::Vector2d moved_at_W_{NAN, NAN};
  double moved_s_ = 0;
  bool path_done_ = false;
};

// How the loop ended, for the evaluation's checks: a robot that stopped short of the path's end (2 s and more
// without moving) with where it stands and what it touches.
evaluation::RunEnd run_end(const config::Scenario& s, const RunOptions& options, const RunResult& r,
                           const RunHooks& hooks, const pipeline::Pipeline& pipeline, const sim::World& world) {
  evaluation::RunEnd end;
  end.path_required = s.stop_at_path_end;
  end.duration_s = s.duration_s;
  end.cut_short_from_s = options.cut_short_from_s;
  end.path_required_when_cut_short = options.require_path;
  end.fell = r.fell, end.fell_at_s = r.fell_at_s;
  if (r.fell) end.tilt_rad = pipeline.simulator().robot().tilt_rad();
  end.path_done = hooks.path_done();
  if (end.path_required && !end.path_done && !end.fell && r.frames > 0 && r.sim_time_s - hooks.moved_s() >= 2.0)
    end.blocked =
        evaluation::blocked_diagnosis(r.path_W.back(), hooks.moved_s(), s.pipeline.path.waypoints_W.back(),
                                      sim::robot_contacts(world, pipeline.simulator().robot().base_body_id()));
  end.frames = r.frames;
  end.time_s = r.sim_time_s;
  end.soak = r.soak;
  return end;
}

// Before the frame loop: a nav2 layer's own costmap is what the evaluation scores, and the sampled frames' folder
// must be writable.
void prepare_run(const config::Scenario& s, const RunOptions& options, const layer::Layer& layer,
                 evaluation::RunEvaluation& evaluation) {
  if (s.pipeline.layer_type != layer::LayerType::kStvl)
    evaluation.set_layer_costmap([&layer] { return layer.costmap(); });
  if (!options.out_dir.empty()) ensure_writable_directory(std::filesystem::path(options.out_dir) / "frames");
}

FrameLoopSettings loop_settings(const config::Scenario& s, const RunOptions& options) {
  FrameLoopSettings settings;
  settings.bag_path = options.bag_path;
  if (!options.bag_path.empty())
    settings.bag = bag_settings(options.bag_path, options.bag_format, options.bag_compression, options.bag_topics);
  settings.publish_period_s = s.outputs.publish_period_s;
  settings.stop_requested = options.stop_requested;
  return settings;
}

// After the frame loop (r holds its result): the verdict against the truth at the last frame (`last`, null when
// there was none), the checks, nav2's master costmap, and the layer's files.
void conclude(const config::Scenario& s, const RunOptions& options, const RunHooks& hooks,
              const pipeline::Pipeline& pipeline, const pipeline::Frame* last, evaluation::RunEvaluation& evaluation,
              layer::Layer& layer, ClosedLoop* closed_loop, RunResult& r) {
  // The world and the outage counts at the loop's end are the last frame's (a pipeline running ahead may have
  // simulated two frames further; otherwise they are the pipeline's own).
  const sim::World& end_world = last ? *last->world : pipeline.simulator().world();
  evaluation::RunVerdict verdict =
      evaluation.finish(run_end(s, options, r, hooks, pipeline, end_world), end_world, layer.voxels());
  r.evaluation = std::move(verdict.evaluation);
  r.top_down = std::move(verdict.top_down);
  r.evaluation_phases = verdict.phases;
  r.map_view = std::move(verdict.map_view);
  r.outages = std::move(verdict.outages);
  r.checks = std::move(verdict.checks);
  for (std::size_t c = 0; c < r.camera_timing.size(); ++c)  // timing that starves the map fails the run
    if (const CameraTimingStats& t = r.camera_timing[c]; t.captured > 0 && t.delivered == 0) {
      std::string reasons;
      for (const auto& [reason, n] : t.dropped)
        reasons += (reasons.empty() ? "" : ", ") + reason + " " + std::to_string(n);
      r.checks.push_back({"frames_reached_map", false,
                          "camera '" + s.pipeline.cameras[c].name + "': none of its " + std::to_string(t.captured) +
                              " frames reached the map (dropped: " + (reasons.empty() ? "none" : reasons) + ")"});
    }
  if (closed_loop) {
    r.drive = closed_loop->finish(r.sim_time_s);
    for (auto& check : evaluation::drive_checks(s.checks, *r.drive, options.cut_short_from_s > 0, options.require_path))
      r.checks.push_back(std::move(check));
  }
  if (const layer::Nav2Costmap* master = layer.master()) {
    r.nav2_master = master->master();
    r.nav2_truth = evaluation.against_truth(*r.nav2_master);
    r.nav2_ghosts = master->ghosts();
    r.nav2_config = master->config();
  }
  for (std::size_t c = 0; c < s.pipeline.cameras.size(); ++c)
    r.skipped_frames.push_back(last ? last->skipped_frames.at(c) : pipeline.skipped_frames(c));
  write_layer_outputs(layer, options.out_dir);
}

}  // namespace

bool RunResult::passed() const {
  for (const auto& c : checks)
    if (c.evaluated && !c.passed) return false;
  return !interrupted;
}

RunResult run_scenario(const config::Scenario& s, const RunOptions& options) {
  RunResult r;
  r.scenario = s;
  const std::unique_ptr<pipeline::Pipeline> pipeline = build_pipeline(s);
  const std::unique_ptr<layer::Layer> the_layer = layer::make_layer(pipeline::layer_config(s.pipeline));
  layer::Layer& layer = *the_layer;
  const sim::World& world = pipeline->simulator().world();
  evaluation::RunEvaluation evaluation(world, config::evaluation_config(s), s.checks, s.pipeline.cameras);
  prepare_run(s, options, layer, evaluation);
  r.gl_backend = pipeline->gl_backend();
  r.filter_device = pipeline->filter_device();
  const FrameLoopSettings settings = loop_settings(s, options);
  SimulatedFrames frames(*pipeline, s.duration_s, evaluation.truth());
  std::unique_ptr<ClosedLoop> closed_loop;
  if (s.navigation.mode == navigation::NavigationMode::kClosedLoop)
    closed_loop = std::make_unique<ClosedLoop>(s, *pipeline, layer, evaluation, !options.bag_path.empty());
  RunHooks hooks(s, options, evaluation, closed_loop.get());
  if (s.pipeline.timing_enabled()) {  // frames as the robot's subscriber gets them (issue 43)
    TimedFrames timed(frames, *pipeline, s.pipeline.seed, s.duration_s, closed_loop != nullptr);
    timed.set_lost_observer([&](const pipeline::Frame& f, double t) {
      evaluation.observe_lost(f, t, world);
      if (closed_loop) closed_loop->after_lost_frame(t);
    });
    static_cast<FrameLoopResult&>(r) = run_frame_loop(timed, layer, hooks, settings);
    r.camera_timing = timed.stats();
    r.frame_events = timed.events();
    r.localization = timed.localization();
    r.corrections = pipeline->simulator().corrections();
  } else {
    if (options.run_ahead && !closed_loop) frames.run_ahead();
    static_cast<FrameLoopResult&>(r) = run_frame_loop(frames, layer, hooks, settings);
  }
  frames.stop();
  hooks.finish();
  r.soak = hooks.soak();
  if (r.interrupted) return r;  // no result file is written

  conclude(s, options, hooks, *pipeline, frames.last(), evaluation, layer, closed_loop.get(), r);
  return r;
}

bool can_share_drive(const config::Scenario& s) {
  return s.navigation.mode != navigation::NavigationMode::kClosedLoop && !s.pipeline.timing_enabled();
}

std::vector<RunResult> run_twins(const std::vector<config::Scenario>& scenarios,
                                 const std::vector<RunOptions>& options) {
  if (scenarios.empty() || scenarios.size() != options.size())
    throw std::invalid_argument("run_twins: " + std::to_string(scenarios.size()) + " scenarios, " +
                                std::to_string(options.size()) + " option sets");
  for (const auto& s : scenarios)
    if (!can_share_drive(s))
      throw std::invalid_argument("run_twins: '" + s.name + "' drives in closed loop or with camera timing");
  const std::size_t n = scenarios.size();
  const std::unique_ptr<pipeline::Pipeline> pipeline = build_pipeline(scenarios.front());
  const sim::World& world = pipeline->simulator().world();
  // Each twin's layer, evaluation (its truth made now, from the world before the drive starts) and hooks.
  struct Twin {
    Twin(const config::Scenario& s, const RunOptions& options, const sim::World& world)
        : layer(layer::make_layer(pipeline::layer_config(s.pipeline))),
          evaluation(world, config::evaluation_config(s), s.checks, s.pipeline.cameras),
          hooks(s, options, evaluation, nullptr) {}
    std::unique_ptr<layer::Layer> layer;
    evaluation::RunEvaluation evaluation;
    RunHooks hooks;
    std::unique_ptr<TwinFrames> frames;
    RunResult result;
    std::exception_ptr error;
  };
  std::vector<std::unique_ptr<Twin>> twins;
  for (std::size_t i = 0; i < n; ++i) {
    const config::Scenario& s = scenarios[i];
    twins.push_back(std::make_unique<Twin>(s, options[i], world));
    Twin& t = *twins.back();
    prepare_run(s, options[i], *t.layer, t.evaluation);
    t.result.scenario = s;
    t.result.gl_backend = pipeline->gl_backend();
  }
  SharedDrive drive(*pipeline, n, scenarios.front().duration_s);
  std::vector<std::thread> threads;
  for (std::size_t i = 0; i < n; ++i) {
    Twin& t = *twins[i];
    t.frames = std::make_unique<TwinFrames>(drive, i, scenarios[i].pipeline, t.evaluation.truth());
    t.result.filter_device = t.frames->filter_device();
    threads.emplace_back([&, i] {
      Twin& twin = *twins[i];
      try {
        static_cast<FrameLoopResult&>(twin.result) =
            run_frame_loop(*twin.frames, *twin.layer, twin.hooks, loop_settings(scenarios[i], options[i]));
        twin.hooks.finish();
        twin.result.soak = twin.hooks.soak();
        // Before leaving: the last frame's world is the drive's snapshot, kept until then.
        if (!twin.result.interrupted)
          conclude(scenarios[i], options[i], twin.hooks, *pipeline, twin.frames->last(), twin.evaluation, *twin.layer,
                   nullptr, twin.result);
      } catch (...) {
        twin.error = std::current_exception();
        drive.stop();  // the others end at their next frame: the command fails anyway
      }
      drive.leave(i);
    });
  }
  for (std::thread& thread : threads) thread.join();
  std::vector<RunResult> results;
  for (auto& t : twins) {
    if (t->error) std::rethrow_exception(t->error);
    results.push_back(std::move(t->result));
  }
  return results;
}

}  // namespace stvl::run

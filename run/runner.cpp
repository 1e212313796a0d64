#include "run/runner.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>

#include "common/atomic_file.hpp"
#include "common/stopwatch.hpp"
#include "pipeline/pipeline.hpp"
#include "run/bag_recorder.hpp"
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

}  // namespace

bool RunResult::passed() const {
  for (const auto& c : checks)
    if (c.evaluated && !c.passed) return false;
  return !interrupted;
}

RunResult run_scenario(const config::Scenario& s, const RunOptions& options) {
  RunResult r;
  r.scenario = s;
  const std::filesystem::path out = options.out_dir;
  const std::unique_ptr<pipeline::Pipeline> owned = build_pipeline(s);
  pipeline::Pipeline& pipeline = *owned;
  const sim::World& world = pipeline.simulator().world();
  evaluation::RunEvaluation evaluation(world, config::evaluation_config(s), s.checks, s.pipeline.cameras);
  if (!options.out_dir.empty()) ensure_writable_directory(out / "frames");
  r.gl_backend = pipeline.gl_backend();
  r.filter_device = pipeline.filter_device();
  std::unique_ptr<BagRecorder> bag;
  if (!options.bag_path.empty())
    bag = std::make_unique<BagRecorder>(
        options.bag_path, bag_settings(options.bag_path, options.bag_format, options.bag_compression, options.bag_topics),
        pipeline, evaluation.truth().voxel_centers());
  std::vector<FrameSampler> samplers;
  const bool several = s.pipeline.cameras.size() > 1;
  for (const auto& c : s.pipeline.cameras)
    samplers.emplace_back(options.out_dir.empty() ? std::filesystem::path() : out / "frames",
                          s.outputs.sample_depth_frames, s.duration_s, c.intrinsics.rate_hz, several ? c.name + "_" : "");
  r.camera_times.resize(s.pipeline.cameras.size());

  MapPublishClock publish(s.outputs.publish_period_s, MapPublishClock::Grid::kFixed);
  Progress progress(options.progress, s.duration_s);
  evaluation::SoakSampler soak(s.outputs.soak_sample_every_s);
  evaluation::RunEnd end;
  end.path_required = s.stop_at_path_end;
  end.duration_s = s.duration_s;
  end.cut_short_from_s = options.cut_short_from_s;
  end.path_required_when_cut_short = options.require_path;
  const auto wall_start = SteadyClock::now();
  Eigen::Vector2d moved_at_W(NAN, NAN);  // where the robot last moved by more than 2 cm, and when
  double moved_s = 0;
  const auto before_map_update = [&](const pipeline::FrameResult& f, const mapping::VoxelMap& map) {
    evaluation.before_update(f, world, map);
  };

  while (pipeline.next_time_s() <= s.duration_s + 1e-9) {
    if (options.stop_requested && options.stop_requested->load()) {
      r.interrupted = true;
      break;
    }
    const pipeline::FrameResult& f = pipeline.step(before_map_update);
    if (!f.robot_upright) {
      end.fell = true, end.fell_at_s = f.time_s, end.tilt_rad = pipeline.simulator().robot().tilt_rad();
      break;
    }
    evaluation.after_update(f, world, pipeline.map());
    samplers[f.camera_index].offer(f, s.pipeline.cameras[f.camera_index].intrinsics.min_range_m);
    const auto bag_start = SteadyClock::now();
    // The map goes into the bag after an update (with several cameras at one instant: after the last of them).
    if (bag) bag->record(f, pipeline, f.map_updated && publish.due(f.time_s));

    r.path_W.emplace_back(f.T_world_base.translation().head<2>());
    if (!((r.path_W.back() - moved_at_W).norm() <= 0.02)) moved_at_W = r.path_W.back(), moved_s = f.time_s;
    r.times.append(f.times);
    r.camera_times[f.camera_index].append(f.times);
    r.times.evaluation.push_back(evaluation.last_frame_ms());
    r.times.bag.push_back(ms_since(bag_start));
    r.times.frame.push_back(f.times.render_ms + f.times.noise_ms + f.times.cloud_ms + f.times.filter_ms +
                            f.times.clear_ms + f.times.mark_ms + r.times.evaluation.back() + r.times.bag.back());
    r.points_raw.push_back(static_cast<std::size_t>(f.point_count));
    r.points_filtered.push_back(static_cast<std::size_t>(f.marking_W.cols()));
    r.map_voxels.push_back(pipeline.map().size());
    soak.frame(f.time_s, f.times.clear_ms + f.times.mark_ms, f.times.map_cpu_ms,
               pipeline.simulator().laps_completed(), pipeline.map());
    r.frames += 1;
    r.footprint_voxels_cleared += f.footprint_cleared;
    r.sim_time_s = f.time_s;
    progress.update(f.time_s, r.frames);
    if (s.stop_at_path_end && f.map_updated && pipeline.simulator().path_finished()) {
      end.path_done = true;
      break;
    }
  }
  progress.done();
  r.wall_time_s = s_since(wall_start);
  r.real_time_factor = r.wall_time_s > 0 ? r.sim_time_s / r.wall_time_s : 0;
  r.soak = soak.series();
  if (r.interrupted) return r;  // the bag stays as <bag>.active; no result file is written

  // A robot that stopped short of the path's end (2 s and more without moving): where, and what it touches.
  if (end.path_required && !end.path_done && !end.fell && r.frames > 0 && r.sim_time_s - moved_s >= 2.0)
    end.blocked = evaluation::blocked_diagnosis(r.path_W.back(), moved_s, s.pipeline.path.waypoints_W.back(),
                                                sim::robot_contacts(world, pipeline.simulator().robot().base_body_id()));
  end.frames = r.frames;
  end.time_s = r.sim_time_s;
  end.soak = r.soak;
  evaluation::RunVerdict verdict = evaluation.finish(end, world, pipeline.map());
  r.evaluation = std::move(verdict.evaluation);
  r.top_down = std::move(verdict.top_down);
  r.evaluation_phases = verdict.phases;
  r.map_view = std::move(verdict.map_view);
  r.outages = std::move(verdict.outages);
  r.checks = std::move(verdict.checks);
  r.sources = pipeline.source_status(r.sim_time_s);
  if (const mapping::Nav2Costmap* nav2 = pipeline.nav2_costmap()) {
    r.nav2_master = nav2->master();
    r.nav2_truth = evaluation.against_truth(*r.nav2_master);
  }
  r.nav2_ghosts = pipeline.nav2_ghosts();
  for (std::size_t c = 0; c < s.pipeline.cameras.size(); ++c) r.skipped_frames.push_back(pipeline.skipped_frames(c));
  if (bag) {
    // The bag ends with the final map, the one map.vdb and costmap.pgm hold.
    if (r.frames > 0 && publish.final_due(r.sim_time_s)) bag->record_map(r.sim_time_s, pipeline);
    bag->close();
  }
  if (!options.out_dir.empty()) {
    pipeline.map().save_vdb((out / "map.vdb").string());
    pipeline.map().save_ply((out / "map.ply").string());  // deterministic bytes (a .vdb file carries a random UUID)
    if (!pipeline.map().empty()) mapping::write_costmap(pipeline.costmap(), (out / "costmap").string());
    if (r.nav2_master) mapping::write_costmap(*r.nav2_master, (out / "nav2_costmap").string());
  }
  return r;
}

}  // namespace stvl::run

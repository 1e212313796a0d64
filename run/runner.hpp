#pragma once
// Runs one scenario end to end: the pipeline's simulated frames through STVL's layer in the frame loop
// (frame_loop.hpp), each frame judged by the run's evaluation (evaluation/run_evaluation.hpp) against the truth;
// then the verdict, the map and the costmaps.
#include <optional>
#include <string>
#include <vector>

#include "config/scenario.hpp"
#include "evaluation/drive.hpp"
#include "evaluation/run_evaluation.hpp"
#include "run/frame_loop.hpp"
#include "run/timed_frames.hpp"

namespace stvl::run {

// The frame loop's series (path_W: the robot's true position at each frame; sources: each source's staleness and
// re-applied readings, evaluation.failure_modes.outage), and what the evaluation concluded.
struct RunResult : FrameLoopResult {
  config::Scenario scenario;
  evaluation::MapView map_view;
  evaluation::EvaluationSummary evaluation;
  evaluation::TopDown top_down;
  evaluation::PhaseTimes evaluation_phases;  // totals over the run
  std::vector<evaluation::CheckResult> checks;
  std::string gl_backend, filter_device;
  // Camera outages: each camera's frames not taken, each outage's result.
  std::vector<std::size_t> skipped_frames;
  // Cameras with timing (camera.timing, tf): per camera, what their latency, stamps, drops and the tf message
  // filter did to their frames (run/timed_frames.hpp); empty for a run without timing.
  std::vector<CameraTimingStats> camera_timing;
  std::vector<TimedFrameEvent> frame_events;  // every settled frame's fate (report.html's timing chart)
  // With localization: what its corrections did, and each one (report.html's timing chart).
  LocalizationStats localization;
  std::vector<sim::LocalizationCorrection> corrections;
  std::vector<evaluation::OutageResult> outages;

  // With map.nav2_costmap: nav2's master costmap at the end and its ghosts over the run.
  std::optional<mapping::Costmap2D> nav2_master;
  layer::Nav2Ghosts nav2_ghosts;
  layer::Nav2CostmapConfig nav2_config;  // the master's window as the layer ran it (a nav2 layer's default included)
  evaluation::LethalVsTruth nav2_truth;  // nav2_master's lethal cells against the final truth

  evaluation::SoakSeries soak;  // evaluation.soak_sample_every_s > 0 only
  // navigation.mode closed_loop: what the drive cost, against the truth (evaluation/drive.hpp).
  std::optional<evaluation::DriveSummary> drive;
  // Every check passed and the run was not interrupted.
  bool passed() const;
};

// Throws std::invalid_argument / std::runtime_error for bad input or environment (exit code 2).
RunResult run_scenario(const config::Scenario& scenario, const RunOptions& options);

// Whether the scenario's frames are made whatever its layer does: not in closed loop, not with camera timing.
bool can_share_drive(const config::Scenario& scenario);

// Twins: scenarios that differ only in what is done with the frames (run/shared_drive.hpp's twin_sets_problem:
// the layer, filter, evaluation, checks, outputs, edge filter; the caller ensures it), run on one drive, each with its
// options and on a thread of its own. Each result is run_scenario's for that scenario and options (timings
// aside); the first scenario's simulator, cameras and noise make the frames. Throws std::invalid_argument for a
// scenario that cannot share its drive (can_share_drive), and what run_scenario throws (a twin's error once all
// have ended).
std::vector<RunResult> run_twins(const std::vector<config::Scenario>& scenarios,
                                 const std::vector<RunOptions>& options);

}  // namespace stvl::run

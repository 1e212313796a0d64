#pragma once
// Runs one scenario end to end: builds the pipeline, steps it frame by frame, hands each frame to the run's
// evaluation (evaluation/run_evaluation.hpp) and to the outputs (bag, sample depth frames), then writes the map.
#include <optional>
#include <string>
#include <vector>

#include "config/scenario.hpp"
#include "evaluation/run_evaluation.hpp"
#include "run/frame_outputs.hpp"

namespace stvl::run {

struct RunResult {
  config::Scenario scenario;
  evaluation::MapView map_view;
  evaluation::EvaluationSummary evaluation;
  evaluation::TopDown top_down;
  StageSeries times;
  std::vector<StageSeries> camera_times;  // per camera index: its frames' render .. mark
  evaluation::PhaseTimes evaluation_phases;  // totals over the run
  std::vector<evaluation::CheckResult> checks;
  std::vector<Eigen::Vector2d> path_W;  // the robot's true position at each frame
  std::vector<std::size_t> points_raw, points_filtered, map_voxels;  // per frame
  std::size_t frames = 0;
  std::size_t footprint_voxels_cleared = 0;  // map.clear_footprint_voxels_below (ours), summed over the updates
  double sim_time_s = 0;
  double wall_time_s = 0;
  double real_time_factor = 0;  // simulated seconds per wall-clock second
  bool interrupted = false;
  std::string gl_backend, filter_device;
  // Camera outages and STVL's source buffers (evaluation.failure_modes.outage): each source's staleness and
  // re-applied readings, each camera's frames not taken (outages), each outage's result.
  std::vector<pipeline::SourceStatus> sources;
  std::vector<std::size_t> skipped_frames;
  std::vector<evaluation::OutageResult> outages;

  // With map.nav2_costmap: nav2's master costmap at the end and its ghosts over the run.
  std::optional<mapping::Costmap2D> nav2_master;
  pipeline::Nav2Ghosts nav2_ghosts;
  evaluation::LethalVsTruth nav2_truth;  // nav2_master's lethal cells against the final truth

  evaluation::SoakSeries soak;  // evaluation.soak_sample_every_s > 0 only
  // Every check passed and the run was not interrupted.
  bool passed() const;
};

// Throws std::invalid_argument / std::runtime_error for bad input or environment (exit code 2).
RunResult run_scenario(const config::Scenario& scenario, const RunOptions& options);

}  // namespace stvl::run

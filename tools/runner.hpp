#pragma once
// Runs one scenario end to end: builds the pipeline, steps it frame by frame, hands each frame to the
// evaluation and to the outputs (bag, sample depth frames), then checks the result.
#include <atomic>
#include <string>
#include <vector>

#include "evaluation/evaluator.hpp"
#include "tools/checks.hpp"
#include "tools/scenario.hpp"
#include "tools/soak.hpp"

namespace stvl::tools {

struct RunOptions {
  std::string out_dir;           // empty: no files
  std::string bag_path;          // empty: no bag
  std::string bag_compression = "none";
  bool progress = true;          // progress bar on a TTY, plain lines otherwise
  const std::atomic<bool>* stop_requested = nullptr;  // set from a signal handler
};

struct StageTimes {
  // Wall-clock milliseconds per frame; timings are the only part of a run that is not deterministic.
  std::vector<double> render, noise, cloud, filter, clear, mark, evaluation, bag, frame;
};

struct RunResult {
  Scenario scenario;
  evaluation::EvaluationSummary evaluation;
  evaluation::TopDown top_down;
  StageTimes times;
  std::vector<StageTimes> camera_times;  // per camera index: its frames' render .. mark
  evaluation::PhaseTimes evaluation_phases;  // totals over the run
  std::vector<CheckResult> checks;
  std::vector<Eigen::Vector2d> path_W;  // the robot's true position at each frame
  std::vector<std::size_t> points_raw, points_filtered, map_voxels;  // per frame
  std::size_t frames = 0;
  double sim_time_s = 0;
  double wall_time_s = 0;
  double real_time_factor = 0;  // simulated seconds per wall-clock second
  bool interrupted = false;
  std::string gl_backend, filter_device;
  SoakSeries soak;  // evaluation.soak_sample_every_s > 0 only
  bool passed() const;
};

// Throws std::invalid_argument / std::runtime_error for bad input or environment (exit code 2).
RunResult run_scenario(const Scenario& scenario, const RunOptions& options);

}  // namespace stvl::tools

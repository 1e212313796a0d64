#pragma once
// Runs one scenario end to end: builds the pipeline, steps it frame by frame, hands each frame to the
// evaluation and to the outputs (bag, sample depth frames), then checks the result.
#include <atomic>
#include <filesystem>
#include <string>
#include <vector>

#include "evaluation/evaluator.hpp"
#include "evaluation/outage.hpp"
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

// The final map for the report's 3D view, world frame: mapped voxel centres within the evaluation's tolerance of
// the truth, the other mapped ones, and the truth's voxel centres; each thinned to about max_points (chosen by a
// hash of the voxel key, so the view is spread evenly and deterministic).
// Without ground truth (a replayed recording) every mapped voxel is unjudged.
struct MapView {
  double voxel_size_m = 0;
  Eigen::Matrix3Xf mapped_true_W, mapped_false_W, truth_W, unjudged_W;
  std::size_t mapped_true = 0, mapped_false = 0, truth = 0, unjudged = 0;  // before thinning
};
MapView make_map_view(const mapping::VoxelMap& map, const evaluation::Truth& truth, int tolerance_voxels,
                      std::size_t max_points = 60000);
MapView make_map_view(const mapping::VoxelMap& map, std::size_t max_points = 60000);

// A depth frame for the report: <frames_dir>/<prefix>depth_NNNNN.png (16-bit mm) and ..._color.png (near blue to
// far red over min_range_m .. 6 m), each written atomically.
void write_sample_depth_frame(const std::filesystem::path& frames_dir, const std::string& prefix, std::size_t frame_index,
                              const sensors::DepthImage& depth, double min_range_m);

struct RunResult {
  Scenario scenario;
  MapView map_view;
  evaluation::EvaluationSummary evaluation;
  evaluation::TopDown top_down;
  StageTimes times;
  std::vector<StageTimes> camera_times;  // per camera index: its frames' render .. mark
  evaluation::PhaseTimes evaluation_phases;  // totals over the run
  std::vector<CheckResult> checks;
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

  SoakSeries soak;  // evaluation.soak_sample_every_s > 0 only
  bool passed() const;
};

// Throws std::invalid_argument / std::runtime_error for bad input or environment (exit code 2).
RunResult run_scenario(const Scenario& scenario, const RunOptions& options);

}  // namespace stvl::tools

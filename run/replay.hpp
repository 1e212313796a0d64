#pragma once
// Recorded depth (recording/) through the same stages as a simulated camera's frames (pipeline/map_stages.hpp):
// edge filter, depth to cloud, decimation, STVL's clear and mark, in recorded time. A replay has no ground
// truth: it writes what a run writes but the truth's figures and checks (report/report.hpp).
#include <atomic>
#include <filesystem>
#include <string>
#include <vector>

#include "recording/recording.hpp"
#include "evaluation/map_view.hpp"
#include "pipeline/frame.hpp"
#include "run/frame_outputs.hpp"

namespace stvl::run {

struct ReplaySettings {
  // A scenario's pipeline: its first camera's sources and edge filter, the filter and the map are used; the
  // camera takes the recording's intrinsics and is named camera_name; world, robot and noise are not used.
  pipeline::PipelineConfig pipeline;
  std::string camera_name = "camera";
  recording::RecordingOptions recording;
  std::size_t max_frames = 0;     // 0: every frame
  int sample_depth_frames = 3;    // depth frames saved as PNG for the report
  double publish_period_s = 1.0;  // the bag's map and costmap
};

struct ReplayResult {
  recording::RecordingInfo recording;
  pipeline::PipelineConfig pipeline;  // as replayed: one camera with the recording's intrinsics
  StageSeries times;                  // cloud, filter, clear, mark, bag and frame (no render, noise, evaluation)
  std::vector<std::size_t> points_raw, points_filtered, map_voxels;  // per frame
  std::vector<double> valid_fraction;  // per frame: pixels with depth
  std::vector<Eigen::Vector2d> path_W;  // base_link per frame, in the recording's fixed frame
  std::vector<std::size_t> sampled_frames;  // indices of the depth frames saved under frames/
  evaluation::MapView map_view;                    // every voxel unjudged (no truth)
  mapping::Costmap2D costmap;           // the final map's, footprint freed at the last base pose
  std::size_t frames = 0, final_voxels = 0, lethal_cells = 0;
  double recorded_s = 0, wall_time_s = 0, real_time_factor = 0;
  std::string filter_device;
  std::vector<pipeline::SourceStatus> sources;
  bool interrupted = false;
};

// Replays an opened recording (recording::open_recording) from its next frame. The camera's observation sources
// take the recording's FOV where they had the scenario camera's (a FOV a scenario or parameter file gives is
// kept). Throws std::invalid_argument for bad input (a frame that cannot be read, one whose intrinsics differ
// from the first's, stamps that go back in time) and std::runtime_error for unwritable outputs.
ReplayResult replay_recording(recording::Recording& recording, const ReplaySettings& settings, const RunOptions& options);

}  // namespace stvl::run

#pragma once
// Recorded depth (recording/) through the same frame loop as a simulated run (frame_loop.hpp): the same sensing
// (pipeline/sensing.hpp: edge filter, depth to cloud, decimation) and STVL's layer, in recorded time. A replay has no
// ground truth: it writes what a run writes but the truth's figures and checks (report/report.hpp).
#include <atomic>
#include <filesystem>
#include <string>
#include <vector>

#include "evaluation/map_view.hpp"
#include "pipeline/config.hpp"
#include "recording/recording.hpp"
#include "run/frame_loop.hpp"

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

// The frame loop's series (times: cloud, filter, clear, mark, bag and frame; render, noise and evaluation are 0;
// path_W: base_link per frame in the recording's fixed frame; sim_time_s: the last frame's recorded stamp), and
// what only a replay has.
struct ReplayResult : FrameLoopResult {
  recording::RecordingInfo recording;
  pipeline::PipelineConfig pipeline;        // as replayed: one camera with the recording's intrinsics
  std::vector<double> valid_fraction;       // per frame: pixels with depth
  std::vector<std::size_t> sampled_frames;  // indices of the depth frames saved under frames/
  evaluation::MapView map_view;             // every voxel unjudged (no truth)
  mapping::Costmap2D costmap;               // the final map's, footprint freed at the last base pose
  std::size_t final_voxels = 0, lethal_cells = 0;
  std::string filter_device;
};

// Replays an opened recording (recording::open_recording) from its next frame. The camera's observation sources
// take the recording's FOV where they had the scenario camera's (a FOV a scenario or parameter file gives is
// kept). Throws std::invalid_argument for bad input (a frame that cannot be read, one whose intrinsics differ
// from the first's, stamps that go back in time) and std::runtime_error for unwritable outputs.
ReplayResult replay_recording(recording::Recording& recording, const ReplaySettings& settings,
                              const RunOptions& options);

}  // namespace stvl::run

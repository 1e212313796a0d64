#pragma once
// What happens to a depth image once a camera has it, for rendered frames (Pipeline) and recorded ones (the
// replay) alike: sense() runs the camera's edge filter, depth to cloud, the world transform and the decimation;
// update() is STVL's map update from the observation sources' buffers: the frame's reading and the readings
// STVL applies again, cleared then marked, then the footprint clearing of ours.
//
//   MapStages stages(config);
//   frame.depth = ...; frame.T_world_camera = ...; frame.camera_index = ...; frame.time_s = ...;
//   stages.sense(frame);
//   stages.update(frame, cameras_now);
#include <functional>
#include <memory>
#include <vector>

#include "mapping/costmap.hpp"
#include "mapping/voxel_map.hpp"
#include "pipeline/frame.hpp"

namespace stvl::pipeline {

class MapStages {
 public:
  // Keeps a copy of the config: its cameras (sources, edge filter, intrinsics), filter and map; validates nothing
  // itself (validate_cameras() does).
  explicit MapStages(const PipelineConfig& config);
  // Frees the filter, the sources' buffers and the map; not copyable.
  ~MapStages();
  MapStages(const MapStages&) = delete;
  MapStages& operator=(const MapStages&) = delete;

  // From f.depth, f.camera_index and f.T_world_camera: f.edge_filtered_depth, edge_dropped_pixels, points_C,
  // point_count, cloud_W, decimated_W, marking_W, times.cloud_ms and times.filter_ms. With the marking band in
  // base_link (band_frame(), STVL's relative filters) the filter runs on the cloud in base_link (f.T_world_base)
  // and what it keeps goes to the world frame (both transforms in float, as tf2's doTransform), with marking_B.
  void sense(FrameResult& f);

  // Where every camera's optical frame is at an update, and when its next frame is due: a camera that has
  // missed a frame (its last frame is more than a period old and none is pending at the update) has its
  // buffers applied again, as STVL applies every buffer at every update.
  struct CamerasNow {
    std::function<Eigen::Isometry3d(std::size_t camera)> T_world_camera;
    std::function<double(std::size_t camera)> next_frame_time_s;
  };
  // Buffers the frame's reading (f.decimated_W, marking_W, T_world_camera; the no-return rays from f.depth) and
  // runs STVL's update at f.time_s, with f.T_world_base for the footprint: fills f.no_return_W, updates,
  // map_updated, cleared_keys, footprint_cleared, reapplied_readings, times.clear_ms, mark_ms and map_cpu_ms. With
  // map.update_grouping instant, a frame that another camera's frame at the same time follows only buffers
  // (map_updated false); the last frame of the instant updates with every camera's reading of it. With
  // map.update_frequency STVL updates at every tick k / f: the ticks since the last frame run first, at their
  // own times, from the buffers as they were; the frame's own time updates only when it is a tick.
  void update(FrameResult& f, const CamerasNow& now);

  const mapping::VoxelMap& map() const { return map_; }  // as the last update() left it
  // Every source's status (cameras in order, their sources in order), spans of staleness closed at until_s.
  std::vector<SourceStatus> source_status(double until_s) const;
  const char* filter_device() const { return filter_.device_used(); }  // "cpu" or "cuda"
  // With config.nav2_costmap: nav2's master costmap as the last update left it, and its ghosts over the run
  // (master cells lethal where STVL's layer is not, after each update); null / zeros otherwise.
  const mapping::Nav2Costmap* nav2_costmap() const { return nav2_.get(); }
  const Nav2Ghosts& nav2_ghosts() const { return nav2_ghosts_; }

 private:
  struct Sources;
  PipelineConfig config_;
  filter::Filter filter_;
  bool passthrough_ = false;
  mapping::ZReference band_frame_ = mapping::ZReference::kGlobal;
  // The filter stage on cloud (any frame): decimated and marking points in that frame.
  void filter_cloud(const Eigen::Matrix3Xf& cloud, Eigen::Matrix3Xf& decimated, Eigen::Matrix3Xf& marking);
  mapping::VoxelMap map_;
  std::vector<std::unique_ptr<Sources>> cameras_;
  // One STVL update at time_s from the buffers (appended to f.updates; counts into f's figures).
  void run_update(double time_s, FrameResult& f, const CamerasNow& now);
  std::size_t next_update_ = 0;  // with map.update_frequency_hz: the index k of the next update time k / f
  std::unique_ptr<mapping::Nav2Costmap> nav2_;
  Nav2Ghosts nav2_ghosts_;
  // One nav2 cycle after an update at time_s: STVL's layer on the window at the robot, the voxels it removed.
  void update_nav2(double time_s, const Eigen::Isometry3d& T_world_base, const std::vector<VoxelKey>& removed);
};

// The costmap's options: with map.costmap_band marking_band (ours) the marking sources' height band (STVL's
// every_voxel: no band) and, with map.update_footprint_enabled, the footprint
// at T_world_base freed (STVL's footprint clearing at the robot's pose of the last update).
mapping::CostmapOptions costmap_options(const PipelineConfig& config, const Eigen::Isometry3d& T_world_base);

}  // namespace stvl::pipeline

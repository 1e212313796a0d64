#pragma once
// What happens to a depth image once a camera has it, for rendered frames (Pipeline) and recorded ones (the
// replay) alike: the camera's edge filter, depth to cloud, the world transform, the decimation and the marking
// band, and the no-return rays: the frame's observation for the layer.
//
//   Sensing sensing(config);
//   frame.depth = ...; frame.T_world_camera = ...; frame.T_world_base = ...; frame.camera_index = ...;
//   frame.time_s = ...;
//   sensing.sense(frame);  // frame.observation is ready for layer::Layer::update
#include "filter/filter.hpp"
#include "pipeline/config.hpp"
#include "pipeline/frame.hpp"

namespace stvl::pipeline {

class Sensing {
 public:
  // Keeps a copy of the config: its cameras (sources, edge filter, intrinsics), filter and voxel size; validates
  // nothing itself (validate_cameras() does).
  explicit Sensing(const PipelineConfig& config);

  // From f.depth, f.camera_index, f.time_s, f.T_world_camera and f.T_world_base: f.edge_filtered_depth,
  // edge_dropped_pixels, points_C, point_count, cloud_W, a new f.observation, times.cloud_ms and times.filter_ms.
  // With the marking band in base_link (band_frame(), STVL's relative filters) the filter runs on the cloud in
  // base_link and what it keeps goes to the world frame (both transforms in float, as tf2's doTransform), with
  // marking_B. With a clear_on_no_return source the observation's no_return_W from f.depth's pixels without a
  // return.
  void sense(Frame& f);
  const char* filter_device() const { return filter_.device_used(); }  // "cpu" or "cuda"

 private:
  PipelineConfig config_;
  filter::Filter filter_;
  bool passthrough_ = false;
  mapping::ZReference band_frame_ = mapping::ZReference::kGlobal;
  std::vector<double> no_return_range_m_;  // per camera: > 0, the longest max_z of its clear_on_no_return sources
  // The filter stage on cloud (any frame): decimated and marking points in that frame.
  void filter_cloud(const Eigen::Matrix3Xf& cloud, Eigen::Matrix3Xf& decimated, Eigen::Matrix3Xf& marking);
  // The filter stage of f into its observation, in the band's frame.
  void decimate(Frame& f);
};

}  // namespace stvl::pipeline

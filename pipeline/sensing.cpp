#include "pipeline/sensing.hpp"

#include <algorithm>
#include <unordered_set>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "common/stopwatch.hpp"
#include "common/transform_points.hpp"
#include "common/voxel_key.hpp"
#include "filter/passthrough.hpp"

namespace stvl::pipeline {
namespace {

// The first `count` points to another frame in float (Eigen's (R * P).colwise() + t to the bit), blocks of columns
// in parallel (TBB); each column's arithmetic is the same whatever the blocks.
void transform(const Eigen::Isometry3d& T, const Eigen::Matrix3Xf& points, Eigen::Index count, Eigen::Matrix3Xf& out) {
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  out.resize(3, count);
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, count, 16384), [&](const tbb::blocked_range<Eigen::Index>& r) {
    transform_points(R, t, points.data() + 3 * r.begin(), out.data() + 3 * r.begin(), r.size());
  });
}

// One point per voxel of size voxel_m that the rays of depth's pixels without a return reach at range_m from
// the optical centre (the first pixel's in row-major order), in the world frame.
void no_return_points(const sensors::DepthImage& depth, const sensors::CameraIntrinsics& k,
                      const Eigen::Isometry3d& T_world_camera, double range_m, double voxel_m, Eigen::Matrix3Xf& out) {
  std::unordered_set<VoxelKey, VoxelKeyHash> seen;
  std::vector<Eigen::Vector3f> points;
  for (int v = 0; v < depth.height; ++v)
    for (int u = 0; u < depth.width; ++u) {
      if (depth.at(u, v) > 0.0f) continue;
      const Eigen::Vector3d ray_C = sensors::pixel_ray_C(k, u, v);
      const Eigen::Vector3d p_W = T_world_camera * (ray_C * (range_m / ray_C.norm()));
      if (seen.insert(voxel_key(p_W, voxel_m)).second) points.push_back(p_W.cast<float>());
    }
  out.resize(3, Eigen::Index(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i) out.col(Eigen::Index(i)) = points[i];
}

}  // namespace

Sensing::Sensing(const PipelineConfig& config)
    : config_(config),
      filter_(decimation_config(config_.filter)),
      passthrough_(config_.filter.passthrough_enabled || config_.filter.type == filter::FilterType::kPassthrough),
      band_frame_(band_frame(config_)) {
  for (const auto& camera : config_.cameras) {
    double range_m = 0.0;
    for (const auto& source : camera.sources)
      if (source.params.clearing && source.params.clear_on_no_return)
        range_m = std::max(range_m, source.params.max_z_m);
    no_return_range_m_.push_back(range_m);
  }
}

void Sensing::sense(Frame& f) {
  const CameraConfig& camera = config_.cameras.at(f.camera_index);
  auto start = SteadyClock::now();
  const sensors::DepthImage* cloud_depth = &f.depth;
  f.edge_dropped_pixels = 0;
  if (camera.edge_filter.enabled) {
    f.edge_dropped_pixels = sensors::filter_depth_edges(camera.edge_filter, f.depth, f.edge_filtered_depth);
    cloud_depth = &f.edge_filtered_depth;
  } else {
    f.edge_filtered_depth = {};
  }
  f.point_count = sensors::depth_to_cloud(*cloud_depth, camera.intrinsics, f.points_C, f.T_world_camera, f.cloud_W);
  f.observation = std::make_shared<layer::Observation>();
  layer::Observation& o = *f.observation;
  o.sensor_index = f.camera_index;
  o.time_s = f.time_s;
  o.T_world_camera = f.T_world_camera;
  o.T_world_base = f.T_world_base;
  if (no_return_range_m_.at(f.camera_index) > 0.0)
    no_return_points(f.depth, camera.intrinsics, f.T_world_camera, no_return_range_m_[f.camera_index],
                     config_.map.voxel_size_m, o.no_return_W);
  f.times.cloud_ms = ms_since(start);

  start = SteadyClock::now();
  decimate(f);
  f.times.filter_ms = ms_since(start);
}

void Sensing::decimate(Frame& f) {
  layer::Observation& o = *f.observation;
  if (band_frame_ == mapping::ZReference::kBaseLink) {
    // STVL's relative filters: the cloud into base_link (tf's base_link <- camera, in float), filtered there,
    // then what is left into the global frame (tf's global <- base_link, in float again).
    Eigen::Matrix3Xf cloud_B, decimated_B;
    transform(f.T_world_base.inverse() * f.T_world_camera, f.points_C, f.point_count, cloud_B);
    filter_cloud(cloud_B, decimated_B, o.marking_B);
    transform(f.T_world_base, decimated_B, decimated_B.cols(), o.decimated_W);
    transform(f.T_world_base, o.marking_B, o.marking_B.cols(), o.marking_W);
  } else {
    filter_cloud(f.cloud_W, o.decimated_W, o.marking_W);
  }
}

void Sensing::filter_cloud(const Eigen::Matrix3Xf& cloud, Eigen::Matrix3Xf& decimated, Eigen::Matrix3Xf& marking) {
  if (passthrough_ && config_.filter.band_before_decimation) {  // STVL's buffer: the band, then the voxel grid
    marking = filter_.apply(filter::passthrough(cloud, config_.filter.passthrough));
    decimated = marking;
  } else {
    decimated = filter_.apply(cloud);
    marking = passthrough_ ? filter::passthrough(decimated, config_.filter.passthrough) : decimated;
  }
}

}  // namespace stvl::pipeline

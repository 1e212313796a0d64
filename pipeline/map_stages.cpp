#include "pipeline/map_stages.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <unordered_set>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "common/stopwatch.hpp"
#include "mapping/footprint.hpp"

namespace stvl::pipeline {
namespace {

double process_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

// The first `count` points to the world frame, blocks of columns in parallel (TBB); each column's arithmetic is
// the same whatever the blocks.
void transform(const Eigen::Isometry3d& T, const Eigen::Matrix3Xf& points, Eigen::Index count, Eigen::Matrix3Xf& out) {
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  out.resize(3, count);
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, count, 16384), [&](const tbb::blocked_range<Eigen::Index>& r) {
    const Eigen::Index n = Eigen::Index(r.size());
    out.middleCols(r.begin(), n) = (R * points.middleCols(r.begin(), n)).colwise() + t;
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

// One camera's observation sources: their buffers and what they report.
struct MapStages::Sources {
  explicit Sources(const CameraConfig& c) : config(c) {
    for (const auto& source : c.sources) {
      if (source.params.clearing && source.params.clear_on_no_return)
        no_return_range_m = std::max(no_return_range_m, source.params.max_z_m);
      buffers.emplace_back(source.params.observation_persistence_s, source.params.expected_update_rate_s);
      status.push_back({source.name, 0, source.params.expected_update_rate_s, {}, 0, 0.0, 0.0});
    }
  }
  const CameraConfig& config;
  double no_return_range_m = 0.0;  // > 0: the longest max_z of its clear_on_no_return sources
  std::vector<SourceBuffer> buffers;  // one per source
  std::vector<SourceStatus> status;   // one per source
  double last_frame_s = -1.0;         // < 0: none taken yet
  double last_reapplied_s = -1.0;     // the last update time its buffers were applied at another camera's frame
  // It has missed a frame (an outage): one was due after its last and by now_s, and none is pending at now_s
  // (a camera of a higher index with a frame at now_s takes it right after this one).
  bool overdue(double now_s, double next_frame_s) const {
    return last_frame_s >= 0.0 && last_frame_s + 1.0 / config.intrinsics.rate_hz <= now_s + 1e-9 &&
           next_frame_s > now_s + 1e-9;
  }
};

MapStages::MapStages(const PipelineConfig& config)
    : config_(config),
      filter_(decimation_config(config_.filter)),
      passthrough_(config_.filter.passthrough_enabled || config_.filter.type == filter::FilterType::kPassthrough),
      band_frame_(band_frame(config_)),
      map_(config_.map) {
  if (config_.nav2_costmap.enabled()) nav2_ = std::make_unique<mapping::Nav2Costmap>(config_.nav2_costmap);
  for (std::size_t i = 0; i < config_.cameras.size(); ++i) {
    cameras_.push_back(std::make_unique<Sources>(config_.cameras[i]));
    for (auto& status : cameras_.back()->status) status.camera_index = i;
  }
}

MapStages::~MapStages() = default;

std::vector<SourceStatus> MapStages::source_status(double until_s) const {
  std::vector<SourceStatus> all;
  for (const auto& c : cameras_)
    for (std::size_t s = 0; s < c->buffers.size(); ++s) {
      SourceStatus status = c->status[s];
      if (const auto span = stale_span(c->buffers[s].last_updated_s(), until_s, c->buffers[s].expected_update_rate_s()))
        status.stale.push_back(*span);
      all.push_back(std::move(status));
    }
  return all;
}

void MapStages::sense(FrameResult& f) {
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
  f.point_count = sensors::depth_to_cloud(*cloud_depth, camera.intrinsics, f.points_C);
  transform(f.T_world_camera, f.points_C, f.point_count, f.cloud_W);
  f.times.cloud_ms = ms_since(start);

  start = SteadyClock::now();
  if (band_frame_ == mapping::ZReference::kBaseLink) {
    // STVL's relative filters: the cloud into base_link (tf's base_link <- camera, in float), filtered there,
    // then what is left into the global frame (tf's global <- base_link, in float again).
    Eigen::Matrix3Xf cloud_B, decimated_B;
    transform(f.T_world_base.inverse() * f.T_world_camera, f.points_C, f.point_count, cloud_B);
    filter_cloud(cloud_B, decimated_B, f.marking_B);
    transform(f.T_world_base, decimated_B, decimated_B.cols(), f.decimated_W);
    transform(f.T_world_base, f.marking_B, f.marking_B.cols(), f.marking_W);
  } else {
    f.marking_B.resize(3, 0);
    filter_cloud(f.cloud_W, f.decimated_W, f.marking_W);
  }
  f.times.filter_ms = ms_since(start);
}

void MapStages::filter_cloud(const Eigen::Matrix3Xf& cloud, Eigen::Matrix3Xf& decimated, Eigen::Matrix3Xf& marking) {
  if (passthrough_ && config_.filter.band_before_decimation) {  // STVL's buffer: the band, then the voxel grid
    marking = filter_.apply(filter::passthrough(cloud, config_.filter.passthrough));
    decimated = marking;
  } else {
    decimated = filter_.apply(cloud);
    marking = passthrough_ ? filter::passthrough(decimated, config_.filter.passthrough) : decimated;
  }
}

void MapStages::update(FrameResult& f, const CamerasNow& now) {
  Sources& camera = *cameras_.at(f.camera_index);
  auto start = SteadyClock::now();
  const double cpu_start_ms = process_cpu_ms();
  f.no_return_W.resize(3, 0);
  if (camera.no_return_range_m > 0.0)
    no_return_points(f.depth, camera.config.intrinsics, f.T_world_camera, camera.no_return_range_m,
                     config_.map.voxel_size_m, f.no_return_W);
  f.reapplied_readings = 0;
  f.times.mark_ms = 0.0;
  f.updates.clear();
  f.cleared_keys.clear();
  f.footprint_cleared = 0;
  const double frequency_hz = config_.map.update_frequency_hz;
  const auto tick_s = [&](std::size_t k) { return static_cast<double>(k) / frequency_hz; };
  // STVL's layer updates at every tick of the costmap's clock, frames or not: the ticks since the last frame
  // run now, at their own times, with the buffers as they were (this frame's reading has not arrived).
  if (frequency_hz > 0.0)
    for (; tick_s(next_update_) + 1e-9 < f.time_s; ++next_update_) run_update(tick_s(next_update_), f, now);

  auto reading = std::make_shared<SourceReading>();
  reading->time_s = f.time_s;
  reading->T_world_camera = f.T_world_camera;
  reading->decimated_W = f.decimated_W;
  reading->marking_W = f.marking_W;
  reading->marking_B = f.marking_B;
  reading->no_return_W = f.no_return_W;
  for (std::size_t s = 0; s < camera.buffers.size(); ++s) {
    SourceBuffer& buffer = camera.buffers[s];
    if (const auto span = stale_span(buffer.last_updated_s(), f.time_s, buffer.expected_update_rate_s()))
      camera.status[s].stale.push_back(*span);
    buffer.receive(reading);
  }
  camera.last_frame_s = f.time_s;
  const bool instant = config_.map.update_grouping == mapping::UpdateGrouping::kInstant;
  bool update_now = true;
  if (instant)  // another camera still takes a frame at this time: STVL's update of the instant runs at the last
    for (std::size_t index = 0; index < cameras_.size(); ++index)
      if (index != f.camera_index && std::abs(now.next_frame_time_s(index) - f.time_s) <= 1e-9) update_now = false;
  if (frequency_hz > 0.0 && f.time_s + 1e-9 < tick_s(next_update_))
    update_now = false;  // STVL's next update is later: the reading waits in the buffers
  if (update_now) {
    if (frequency_hz > 0.0) ++next_update_;
    run_update(f.time_s, f, now);
  }
  f.map_updated = !f.updates.empty();
  f.times.clear_ms = ms_since(start) - f.times.mark_ms;
  f.times.map_cpu_ms = process_cpu_ms() - cpu_start_ms;
}

void MapStages::run_update(double time_s, FrameResult& f, const CamerasNow& now) {
  FrameResult::MapUpdate& update = f.updates.emplace_back();
  update.time_s = time_s;
  const bool instant = config_.map.update_grouping == mapping::UpdateGrouping::kInstant;
  const bool at_frequency = config_.map.update_frequency_hz > 0.0;
  const auto at_this_instant = [&](double t_s) { return std::abs(t_s - time_s) <= 1e-9; };
  Sources& camera = *cameras_.at(f.camera_index);
  // STVL's update: the readings of every buffer it applies, clearing first, then marking, all at this time.
  std::vector<mapping::ClearingObservation> clearing;
  std::vector<std::pair<const SourceReading*, const mapping::ObservationSource*>> marking;
  for (std::size_t index = 0; index < cameras_.size(); ++index) {
    Sources& c = *cameras_[index];
    // The cameras that took a frame at this instant (this one alone per camera frame), and once per update
    // time the buffers of cameras that have missed a frame.
    // At the update frequency every buffer applies, as STVL's layer reads them all at every update.
    const bool took_frame = (&c == &camera && at_this_instant(c.last_frame_s)) ||
                            (instant && at_this_instant(c.last_frame_s)) || at_frequency;
    if (!took_frame && (!c.overdue(time_s, now.next_frame_time_s(index)) || c.last_reapplied_s >= time_s - 1e-9))
      continue;
    if (!took_frame) c.last_reapplied_s = time_s;
    const Eigen::Vector3d centre_now = now.T_world_camera(index).translation();
    for (std::size_t s = 0; s < c.buffers.size(); ++s) {
      const auto& params = c.config.sources[s].params;
      if (!took_frame && params.drop_when_not_current && !c.buffers[s].current(time_s)) continue;
      for (const auto& r : c.buffers[s].readings()) {
        if (params.clearing || params.marking) update.applied_readings.push_back({index, s, r});
        if (params.clearing) clearing.push_back({r->T_world_camera, params, &r->decimated_W, &r->no_return_W});
        if (params.marking) marking.emplace_back(r.get(), &params);
        if (at_this_instant(r->time_s)) continue;  // this instant's own reading
        ++f.reapplied_readings;
        SourceStatus& status = c.status[s];
        ++status.reapplied_readings;
        status.max_reapplied_age_s = std::max(status.max_reapplied_age_s, time_s - r->time_s);
        status.reapplied_max_distance_m = std::max(status.reapplied_max_distance_m,
                                                   (r->T_world_camera.translation() - centre_now).norm());
      }
    }
  }
  std::vector<VoxelKey> removed;
  map_.clear(clearing, time_s, &f.cleared_keys, nav2_ ? &removed : nullptr);
  const auto start = SteadyClock::now();
  for (const auto& [r, params] : marking) {
    if (params->height_band && params->z_reference != mapping::ZReference::kGlobal) {
      // STVL's relative filters band in base_link; mark() bands in the world only.
      map_.mark(source_marking_W(*r, *params), r->T_world_camera, *params, time_s);
    } else {
      map_.mark(r->marking_W, r->T_world_camera, *params, time_s);
    }
  }
  if (config_.map.footprint_clearing_height_m > 0.0) {
    // Ours: the robot's own voxels inside its footprint, from the floor up to the height given, after marking
    // (at the frame's pose: an update at an earlier tick uses the pose of the frame that ran it).
    const double s = config_.map.voxel_size_m;
    const auto polygon_W = mapping::footprint_in_world(config_.map.footprint_B, f.T_world_base);
    const int top = static_cast<int>(std::ceil(config_.map.footprint_clearing_height_m / s)) - 1;
    std::vector<VoxelKey> keys;
    for (const auto& [ix, iy] : mapping::footprint_cells(polygon_W, Eigen::Vector2d::Zero(), s))
      for (int iz = 0; iz <= top; ++iz) keys.push_back({ix, iy, iz});
    f.footprint_cleared += map_.erase(keys, &f.cleared_keys);
  }
  f.times.mark_ms += ms_since(start);
  if (nav2_) update_nav2(time_s, f.T_world_base, removed);
}

void MapStages::update_nav2(double time_s, const Eigen::Isometry3d& T_world_base, const std::vector<VoxelKey>& removed) {
  const mapping::Costmap2D window = nav2_->window_at(T_world_base.translation().head<2>());
  // STVL's layer: its _cost_map (every voxel of a column, before this update's marks), the footprint freed.
  mapping::CostmapOptions options = costmap_options(config_, T_world_base);
  options.resolution_m = window.resolution_m;
  options.bounds_W = Eigen::AlignedBox2d(
      window.origin_m, window.origin_m + window.resolution_m * Eigen::Vector2d(window.width, window.height));
  mapping::Costmap2D layer = map_.project_costmap(options);
  layer.origin_m = window.origin_m;  // the same corner, exactly
  std::vector<Eigen::Vector2d> cleared_W;
  cleared_W.reserve(removed.size());
  const double s = config_.map.voxel_size_m;
  for (const VoxelKey& k : removed) cleared_W.emplace_back((k.x + 0.5) * s, (k.y + 0.5) * s);
  nav2_->update(layer, cleared_W, options.free_polygon_W);  // the footprint, when STVL frees it (its vertices touch)
  const std::size_t ghosts = nav2_->ghost_cells(layer);
  Nav2Ghosts& g = nav2_ghosts_;
  ++g.updates;
  g.updates_with_ghosts += ghosts > 0;
  g.last_cells = ghosts;
  if (ghosts > g.max_cells) g.max_cells = ghosts, g.max_at_s = time_s;
}

mapping::CostmapOptions costmap_options(const PipelineConfig& config, const Eigen::Isometry3d& T_world_base) {
  mapping::CostmapOptions options;
  if (config.map.costmap_band == mapping::CostmapBand::kMarkingBand) {  // ours; STVL counts every voxel
    const HeightBand band = marking_band(config);
    options.min_obstacle_height_m = band.min_m;
    options.max_obstacle_height_m = band.max_m;
  }
  if (config.map.update_footprint_enabled)  // STVL: at the robot's pose of the last update
    options.free_polygon_W = mapping::footprint_in_world(config.map.footprint_B, T_world_base);
  return options;
}

}  // namespace stvl::pipeline

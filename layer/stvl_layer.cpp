#include "layer/stvl_layer.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "common/stopwatch.hpp"
#include "common/units.hpp"
#include "mapping/footprint.hpp"

namespace stvl::layer {

// One sensor's observation sources: their buffers and what they report.
struct StvlLayer::Sensor {
  explicit Sensor(const SensorConfig& c, std::size_t index) : config(c) {
    for (const auto& source : c.sources) {
      buffers.emplace_back(source.params.observation_persistence_s, source.params.expected_update_rate_s);
      status.push_back({source.name, index, source.params.expected_update_rate_s, {}, 0, 0.0, 0.0});
    }
  }
  const SensorConfig& config;
  std::vector<SourceBuffer> buffers;  // one per source
  std::vector<SourceStatus> status;   // one per source
  double last_frame_s = -1.0;         // < 0: none taken yet
  double last_reapplied_s = -1.0;     // the last update time its buffers were applied at another sensor's frame
  // It has missed a frame (an outage): one was due after its last and by now_s, and none is pending at now_s
  // (a sensor of a higher index with a frame at now_s takes it right after this one).
  bool overdue(double now_s, double next_frame_s) const {
    return last_frame_s >= 0.0 && last_frame_s + 1.0 / config.rate_hz <= now_s + kTimeEpsilon_s &&
           next_frame_s > now_s + kTimeEpsilon_s;
  }
};

// What one update applies: the clearing observations and, in order, the marking readings with their source.
struct StvlLayer::Applied {
  std::vector<mapping::ClearingObservation> clearing;
  std::vector<std::pair<const Observation*, const mapping::ObservationSource*>> marking;
};

StvlLayer::StvlLayer(LayerConfig config) : config_(std::move(config)), map_(config_.map) {
  if (config_.nav2_costmap.enabled()) master_ = std::make_unique<Nav2Costmap>(config_.nav2_costmap);
  for (std::size_t i = 0; i < config_.sensors.size(); ++i)
    sensors_.push_back(std::make_unique<Sensor>(config_.sensors[i], i));
}

StvlLayer::~StvlLayer() = default;

std::vector<SourceStatus> StvlLayer::source_status(double until_s) const {
  std::vector<SourceStatus> all;
  for (const auto& c : sensors_)
    for (std::size_t s = 0; s < c->buffers.size(); ++s) {
      SourceStatus status = c->status[s];
      if (const auto span = stale_span(c->buffers[s].last_updated_s(), until_s, c->buffers[s].expected_update_rate_s()))
        status.stale.push_back(*span);
      all.push_back(std::move(status));
    }
  return all;
}

void StvlLayer::reset(double time_s) {
  // spatio_temporal_voxel_layer.cpp (ros2 branch 0559ae8) reset(): resetMaps() and ResetGrid(), current_ false and
  // was_reset_ (navigation::NavCostmap keeps those), every buffer's ResetLastUpdatedTime; the readings kept. A source
  // stale until now is recorded so before its clock restarts.
  map_.erase(map_.voxel_keys());
  if (master_) master_->reset();
  for (auto& sensor : sensors_)
    for (std::size_t s = 0; s < sensor->buffers.size(); ++s) {
      SourceBuffer& buffer = sensor->buffers[s];
      if (const auto span = stale_span(buffer.last_updated_s(), time_s, buffer.expected_update_rate_s()))
        sensor->status[s].stale.push_back(*span);
      buffer.reset_last_updated(time_s);
    }
}

mapping::Costmap2D StvlLayer::costmap() const { return map_.project_costmap(costmap_options(config_, T_world_base_)); }

void StvlLayer::update(std::shared_ptr<const Observation> observation, const std::vector<SensorNow>& sensors,
                       UpdateReport& report) {
  const Observation& o = *observation;
  Sensor& sensor = *sensors_.at(o.sensor_index);
  const auto start = SteadyClock::now();
  const double cpu_start_ms = process_cpu_ms();
  report.updates.clear();  // cleared, not replaced: the vectors keep their capacity from frame to frame
  report.cleared_keys.clear();
  report.footprint_voxels_cleared = report.reapplied_readings = 0;
  report.mark_ms = 0.0;
  T_world_base_ = o.T_world_base;
  const double frequency_hz = config_.map.update_frequency_hz;
  const auto tick_s = [&](std::size_t k) { return static_cast<double>(k) / frequency_hz; };
  // STVL's layer updates at every tick of the costmap's clock, observations or not: the ticks since the last one
  // run now, at their own times, with the buffers as they were (this observation has not arrived).
  if (frequency_hz > 0.0)
    for (; tick_s(next_tick_) + kTimeEpsilon_s < o.time_s; ++next_tick_)
      run_update(tick_s(next_tick_), o.sensor_index, sensors, report);

  for (std::size_t s = 0; s < sensor.buffers.size(); ++s) {
    SourceBuffer& buffer = sensor.buffers[s];
    if (const auto span = stale_span(buffer.last_updated_s(), o.time_s, buffer.expected_update_rate_s()))
      sensor.status[s].stale.push_back(*span);
    buffer.receive(observation);
  }
  sensor.last_frame_s = o.time_s;
  if (updates_now(o, sensors)) {
    if (frequency_hz > 0.0) ++next_tick_;
    run_update(o.time_s, o.sensor_index, sensors, report);
  }
  report.clear_ms = ms_since(start) - report.mark_ms;
  report.cpu_ms = process_cpu_ms() - cpu_start_ms;
}

bool StvlLayer::current(double time_s) const {
  for (const auto& sensor : sensors_)
    for (const SourceBuffer& buffer : sensor->buffers)
      if (!buffer.current(time_s)) return false;
  return true;
}

bool StvlLayer::updates_now(const Observation& o, const std::vector<SensorNow>& sensors) const {
  if (config_.map.update_grouping == mapping::UpdateGrouping::kInstant)
    // another sensor still takes a frame at this time: STVL's update of the instant runs at the last
    for (std::size_t index = 0; index < sensors_.size(); ++index)
      if (index != o.sensor_index && std::abs(sensors.at(index).next_frame_time_s - o.time_s) <= kTimeEpsilon_s)
        return false;
  const double frequency_hz = config_.map.update_frequency_hz;
  // STVL's next update is later: the reading waits in the buffers
  return !(frequency_hz > 0.0 && o.time_s + kTimeEpsilon_s < static_cast<double>(next_tick_) / frequency_hz);
}

StvlLayer::Applied StvlLayer::collect(double time_s, std::size_t sensor_index, const std::vector<SensorNow>& sensors,
                                      LayerUpdate& update, UpdateReport& report) {
  const bool instant = config_.map.update_grouping == mapping::UpdateGrouping::kInstant;
  const bool at_frequency = config_.map.update_frequency_hz > 0.0;
  const auto at_this_instant = [&](double t_s) { return std::abs(t_s - time_s) <= kTimeEpsilon_s; };
  Applied applied;
  for (std::size_t index = 0; index < sensors_.size(); ++index) {
    Sensor& c = *sensors_[index];
    // The sensors whose frame this instant's update takes (the observation's own sensor alone per frame; every
    // sensor of the instant with update_grouping instant; every buffer at the update frequency, as STVL's layer
    // reads them all at every update), and once per update time the buffers of sensors that have missed a frame.
    const bool frame_of_this_update = (index == sensor_index && at_this_instant(c.last_frame_s)) ||
                                      (instant && at_this_instant(c.last_frame_s)) || at_frequency;
    if (!frame_of_this_update &&
        (!c.overdue(time_s, sensors.at(index).next_frame_time_s) || c.last_reapplied_s >= time_s - kTimeEpsilon_s))
      continue;
    if (!frame_of_this_update) c.last_reapplied_s = time_s;
    const Eigen::Vector3d centre_now = sensors.at(index).T_world_camera.translation();
    for (std::size_t s = 0; s < c.buffers.size(); ++s) {
      const auto& params = c.config.sources[s].params;
      if (!frame_of_this_update && params.drop_when_not_current && !c.buffers[s].current(time_s)) continue;
      for (const auto& r : c.buffers[s].readings()) {
        if (params.clearing || params.marking) update.applied_readings.push_back({index, s, r, nullptr});
        if (params.clearing) applied.clearing.push_back({r->T_world_camera, params, &r->decimated_W, &r->no_return_W});
        if (params.marking) applied.marking.emplace_back(r.get(), &params);
        if (at_this_instant(r->time_s)) continue;  // this instant's own reading
        ++report.reapplied_readings;
        SourceStatus& status = c.status[s];
        ++status.reapplied_readings;
        status.max_reapplied_age_s = std::max(status.max_reapplied_age_s, time_s - r->time_s);
        status.reapplied_max_distance_m =
            std::max(status.reapplied_max_distance_m, (r->T_world_camera.translation() - centre_now).norm());
      }
    }
  }
  return applied;
}

void StvlLayer::run_update(double time_s, std::size_t sensor_index, const std::vector<SensorNow>& sensors,
                           UpdateReport& report) {
  LayerUpdate& update = report.updates.emplace_back();
  update.time_s = time_s;
  // STVL's update: the readings of every buffer it applies, clearing first, then marking, all at this time.
  const Applied applied = collect(time_s, sensor_index, sensors, update, report);
  std::vector<VoxelKey> removed;
  map_.clear(applied.clearing, time_s, &report.cleared_keys, master_ ? &removed : nullptr);
  const auto start = SteadyClock::now();
  for (const auto& [r, params] : applied.marking) {
    if (params->height_band && params->z_reference != mapping::ZReference::kGlobal) {
      // STVL's relative filters band in base_link; mark() bands in the world only.
      map_.mark(source_marking_W(*r, *params), r->T_world_camera, *params, time_s);
    } else {
      map_.mark(r->marking_W, r->T_world_camera, *params, time_s);
    }
  }
  clear_footprint_voxels(report);
  report.mark_ms += ms_since(start);
  if (master_) feed_master(time_s, removed);
}

void StvlLayer::clear_footprint_voxels(UpdateReport& report) {
  if (!(config_.map.clear_footprint_voxels_below_m > 0.0)) return;
  // The robot's own voxels inside its footprint, from the floor up to the height given, after marking (at the
  // observation's pose: an update at an earlier tick uses the pose of the observation that ran it).
  const double s = config_.map.voxel_size_m;
  const auto polygon_W = mapping::footprint_in_world(config_.map.footprint_B, T_world_base_);
  const int top = static_cast<int>(std::ceil(config_.map.clear_footprint_voxels_below_m / s)) - 1;
  std::vector<VoxelKey> keys;
  for (const auto& [ix, iy] : mapping::footprint_cells(polygon_W, Eigen::Vector2d::Zero(), s))
    for (int iz = 0; iz <= top; ++iz) keys.push_back({ix, iy, iz});
  report.footprint_voxels_cleared += map_.erase(keys, &report.cleared_keys);
}

void StvlLayer::feed_master(double time_s, const std::vector<VoxelKey>& removed) {
  const mapping::Costmap2D window = master_->window_at(T_world_base_.translation().head<2>());
  // STVL's layer: its _cost_map (every voxel of a column, before this update's marks), the footprint freed.
  mapping::CostmapOptions options = costmap_options(config_, T_world_base_);
  options.resolution_m = window.resolution_m;
  options.bounds_W = Eigen::AlignedBox2d(
      window.origin_m, window.origin_m + window.resolution_m * Eigen::Vector2d(window.width, window.height));
  mapping::Costmap2D layer = map_.project_costmap(options);
  layer.origin_m = window.origin_m;  // the same corner, exactly
  std::vector<Eigen::Vector2d> cleared_W;
  cleared_W.reserve(removed.size());
  const double s = config_.map.voxel_size_m;
  for (const VoxelKey& k : removed) cleared_W.emplace_back((k.x + 0.5) * s, (k.y + 0.5) * s);
  master_->update(layer, cleared_W, options.free_polygon_W);  // the footprint, when STVL frees it (its vertices touch)
  master_->count_ghosts(time_s, layer);
}

mapping::CostmapOptions costmap_options(const LayerConfig& config, const Eigen::Isometry3d& T_world_base) {
  mapping::CostmapOptions options;
  if (config.map.costmap_band == mapping::CostmapBand::kMarkingBand) {  // the bench's; STVL counts every voxel
    const HeightBand band = marking_band(config.sensors);
    options.min_obstacle_height_m = band.min_m;
    options.max_obstacle_height_m = band.max_m;
  }
  if (config.map.update_footprint_enabled)  // STVL: at the robot's pose of the last update
    options.free_polygon_W = mapping::footprint_in_world(config.map.footprint_B, T_world_base);
  return options;
}

}  // namespace stvl::layer

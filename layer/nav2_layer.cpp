#include "layer/nav2_layer.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/stopwatch.hpp"
#include "common/units.hpp"
#include "mapping/footprint.hpp"

namespace stvl::layer {
namespace {

void reject_range(const std::string& source, const std::string& key, double value) {
  throw std::invalid_argument("observation source '" + source + "': " + key + " = " + std::to_string(value) +
                              ": must be finite and >= 0 m");
}

// The master costmap a nav2 layer lives in: map.nav2_costmap, or a rolling window holding its sources' reach.
Nav2CostmapConfig window_of(const LayerConfig& config) {
  const double resolution_m = config.map.voxel_size_m;
  if (config.nav2_costmap.enabled()) {
    if (std::abs(config.nav2_costmap.resolution_m - resolution_m) > 1e-12)
      throw std::invalid_argument("map.nav2_costmap.resolution_m (" + std::to_string(config.nav2_costmap.resolution_m) +
                                  ") must equal map.voxel_size (" + std::to_string(resolution_m) +
                                  ") for a nav2 layer: they are the one resolution of its grid");
    return config.nav2_costmap;
  }
  double reach_m = 0.0;
  for (const auto& sensor : config.sensors)
    for (const auto& source : sensor.sources)
      reach_m = std::max({reach_m, source.nav2.obstacle_max_range_m, source.nav2.raytrace_max_range_m});
  Nav2CostmapConfig window = config.nav2_costmap;
  window.width_m = window.height_m = 2.0 * reach_m + 1.0;
  window.resolution_m = resolution_m;
  window.rolling_window = true;
  return window;
}

}  // namespace

// One observation source: its nav2 buffer, the bench's observations behind its nav2 ones, and what it reports.
struct Nav2Layer::Source {
  Source(const SourceConfig& c, std::size_t sensor, std::size_t index)
      : sensor_index(sensor), source_index(index), buffer(nav2_params(c), 0) {
    status.source = c.name;
    status.camera_index = sensor;
    status.expected_update_rate_s = c.params.expected_update_rate_s;
  }
  static nav2::Nav2SourceParams nav2_params(const SourceConfig& c) {
    nav2::Nav2SourceParams p;
    p.observation_persistence_s = c.params.observation_persistence_s;
    p.expected_update_rate_s = c.params.expected_update_rate_s;
    p.min_obstacle_height_m = c.params.min_obstacle_height_m;
    p.max_obstacle_height_m = c.params.max_obstacle_height_m;
    p.obstacle_max_range_m = c.nav2.obstacle_max_range_m;
    p.obstacle_min_range_m = c.nav2.obstacle_min_range_m;
    p.raytrace_max_range_m = c.nav2.raytrace_max_range_m;
    p.raytrace_min_range_m = c.nav2.raytrace_min_range_m;
    p.marking = c.params.marking;
    p.clearing = c.params.clearing;
    return p;
  }
  std::size_t sensor_index, source_index;
  nav2::Nav2ObservationBuffer buffer;
  std::map<const nav2::Nav2Observation*, std::shared_ptr<const Observation>> reading_of;
  SourceStatus status;
  double last_updated_s = 0.0;  // nav2's last_updated_: the buffer's creation, then each reception
};

Nav2Layer::Nav2Layer(LayerConfig config) : config_(std::move(config)), voxel_grid_(0, 0, 0) {
  if (config_.type == LayerType::kStvl) throw std::invalid_argument("Nav2Layer: map.layer_type is stvl");
  config_.map.validate();
  config_.nav2.validate();
  if (config_.sensors.empty()) throw std::invalid_argument("Nav2Layer: no sensor");
  for (std::size_t i = 0; i < config_.sensors.size(); ++i) {
    first_source_.push_back(sources_.size());
    for (std::size_t s = 0; s < config_.sensors[i].sources.size(); ++s) {
      const SourceConfig& c = config_.sensors[i].sources[s];
      const std::pair<const char*, double> ranges[] = {{"obstacle_max_range", c.nav2.obstacle_max_range_m},
                                                       {"obstacle_min_range", c.nav2.obstacle_min_range_m},
                                                       {"raytrace_max_range", c.nav2.raytrace_max_range_m},
                                                       {"raytrace_min_range", c.nav2.raytrace_min_range_m}};
      for (const auto& [key, value] : ranges)
        if (!(std::isfinite(value) && value >= 0.0)) reject_range(c.name, key, value);
      sources_.emplace_back(c, i, s);
    }
  }
  master_ = std::make_unique<Nav2Costmap>(window_of(config_));
  const mapping::Costmap2D& m = master_->master();
  const std::uint8_t default_cost = master_->config().track_unknown_space ? nav2::kNoInformation : nav2::kFreeSpace;
  grid_ = nav2::CellGrid(static_cast<unsigned>(m.width), static_cast<unsigned>(m.height), m.resolution_m,
                         m.origin_m.x(), m.origin_m.y(), default_cost);
  if (config_.type == LayerType::kNav2Voxel)
    voxel_grid_.resize(grid_.size_x_cells, grid_.size_y_cells, static_cast<unsigned>(config_.nav2.z_voxels));
  mapping::StvlConfig view_config = config_.map;
  view_config.costmap_timing = mapping::CostmapTiming::kAfterMark;
  view_ = mapping::VoxelMap(view_config);
}

Nav2Layer::~Nav2Layer() = default;

void Nav2Layer::update(std::shared_ptr<const Observation> observation, const std::vector<SensorNow>& sensors,
                       UpdateReport& report) {
  const Observation& o = *observation;
  const double cpu_start_ms = process_cpu_ms();
  report.updates.clear();
  report.cleared_keys.clear();
  report.footprint_voxels_cleared = report.reapplied_readings = 0;
  report.mark_ms = report.clear_ms = 0.0;
  const double frequency_hz = config_.map.update_frequency_hz;
  const auto tick_s = [&](std::size_t k) { return static_cast<double>(k) / frequency_hz; };
  // Costmap2DROS's update loop: the cycles due before this observation arrives run first, with the robot where the
  // last observation left it.
  if (frequency_hz > 0.0)
    for (; tick_s(next_tick_) + kTimeEpsilon_s < o.time_s; ++next_tick_) run_cycle(tick_s(next_tick_), report);
  T_world_base_ = o.T_world_base;
  const auto start_buffering = SteadyClock::now();

  // pointCloud2Callback -> bufferCloud, received now with its header stamp (earlier with camera timing: the purge
  // ages it from there): the decimated cloud in the global frame, the optical centre as the sensor origin.
  const std::int64_t now_ns = nav2::ros_ns_from_seconds(o.time_s);
  const std::int64_t stamp_ns = nav2::ros_ns_from_seconds(o.header_stamp_s());
  const std::size_t end =
      o.sensor_index + 1 < first_source_.size() ? first_source_[o.sensor_index + 1] : sources_.size();
  for (std::size_t i = first_source_.at(o.sensor_index); i < end; ++i) {
    Source& source = sources_[i];
    if (const auto span = stale_span(source.last_updated_s, o.time_s, source.status.expected_update_rate_s))
      source.status.stale.push_back(*span);
    source.buffer.buffer_cloud(o.T_world_camera.translation(), o.decimated_W, stamp_ns, now_ns);
    source.last_updated_s = o.time_s;
    source.reading_of[source.buffer.observations().front().get()] = observation;
    for (auto it = source.reading_of.begin(); it != source.reading_of.end();) {  // forget the purged ones
      const auto& kept = source.buffer.observations();
      const bool held = std::any_of(kept.begin(), kept.end(), [&](const auto& k) { return k.get() == it->first; });
      it = held ? std::next(it) : source.reading_of.erase(it);
    }
  }

  report.clear_ms += ms_since(start_buffering);
  bool cycle_now = true;
  if (frequency_hz > 0.0) {
    cycle_now = std::abs(tick_s(next_tick_) - o.time_s) <= kTimeEpsilon_s;
  } else {
    // once per instant: after the last sensor with a frame at this time
    for (std::size_t index = 0; index < sensors.size() && index < first_source_.size(); ++index)
      if (index != o.sensor_index && std::abs(sensors[index].next_frame_time_s - o.time_s) <= kTimeEpsilon_s)
        cycle_now = false;
  }
  if (cycle_now) {
    if (frequency_hz > 0.0) ++next_tick_;
    run_cycle(o.time_s, report);
  }
  report.cpu_ms = process_cpu_ms() - cpu_start_ms;
}

void Nav2Layer::run_cycle(double time_s, UpdateReport& report) {
  LayerUpdate& update = report.updates.emplace_back();
  update.time_s = time_s;
  const std::int64_t now_ns = nav2::ros_ns_from_seconds(time_s);
  ++cycles_;
  const auto start_roll = SteadyClock::now();
  // LayeredCostmap::updateMap: the master rolls first, then each layer's updateBounds rolls its own grid alike.
  const Eigen::Vector2d robot_W = T_world_base_.translation().head<2>();
  master_->window_at(robot_W);
  if (master_->config().rolling_window) {
    const double size_x_m = (grid_.size_x_cells - 1 + 0.5) * grid_.resolution_m;  // Costmap2D::getSizeInMetersX
    const double size_y_m = (grid_.size_y_cells - 1 + 0.5) * grid_.resolution_m;
    roll_to(robot_W.x() - size_x_m / 2, robot_W.y() - size_y_m / 2);
  }

  nav2::Bounds bounds;
  std::vector<std::shared_ptr<const nav2::Nav2Observation>> marking, clearing;
  std::vector<std::pair<std::size_t, const nav2::Nav2Observation*>> applied;  // source, observation
  const auto gather = [&](bool want_marking, std::vector<std::shared_ptr<const nav2::Nav2Observation>>& out) {
    bool current = true;
    for (std::size_t i = 0; i < sources_.size(); ++i) {
      Source& s = sources_[i];
      if (want_marking ? !s.buffer.params().marking : !s.buffer.params().clearing) continue;
      const std::size_t before = out.size();
      s.buffer.get_observations(now_ns, out);
      for (std::size_t k = before; k < out.size(); ++k) applied.emplace_back(i, out[k].get());
      current = s.buffer.is_current(now_ns) && current;
    }
    return current;
  };
  // The cycle's time: rolling, gathering and raytracing count as clearing, marking, the footprint and the combination
  // as marking (the bench's bookkeeping after it, the view's keys, counts in neither).
  if (config_.type == LayerType::kNav2Voxel) {
    // VoxelLayer::updateBounds: both lists gathered whatever the first says (its current_ is current(time_s)).
    gather(true, marking);
    gather(false, clearing);
    for (const auto& obs : clearing) voxel_raytrace(*obs, bounds);
  } else {
    // ObstacleLayer::updateBounds: the clearing buffers only while every marking one is current.
    if (gather(true, marking)) gather(false, clearing);
    for (const auto& obs : clearing)
      nav2::raytrace_freespace(grid_, obs->origin_W.x(), obs->origin_W.y(), obs->cloud_W, obs->raytrace_max_range_m,
                               obs->raytrace_min_range_m, bounds);
  }
  report.clear_ms += ms_since(start_roll);
  const auto start_mark = SteadyClock::now();
  if (config_.type == LayerType::kNav2Voxel) {
    for (const auto& obs : marking) voxel_mark(*obs, bounds);
  } else {
    nav2::ObstacleMarkingParams params;
    params.min_obstacle_height_m = config_.nav2.min_obstacle_height_m;
    params.max_obstacle_height_m = config_.nav2.max_obstacle_height_m;
    params.range_rule = config_.nav2.marking_range;
    for (const auto& obs : marking) nav2::mark_observation(grid_, *obs, params, bounds);
  }

  report_applied(applied, time_s, update, report);

  // updateFootprint: the footprint's vertices touch the bounds.
  std::vector<Eigen::Vector2d> footprint_W;
  if (config_.nav2.footprint_clearing_enabled && !config_.map.footprint_B.empty()) {
    footprint_W = mapping::footprint_in_world(config_.map.footprint_B, T_world_base_);
    for (const auto& p : footprint_W) bounds.touch(p.x(), p.y());
  }

  update_costs(bounds, footprint_W);
  report.mark_ms += ms_since(start_mark);

  record_cleared_keys(report);
  master_->count_ghosts(time_s, costmap());
}

void Nav2Layer::report_applied(const std::vector<std::pair<std::size_t, const nav2::Nav2Observation*>>& applied,
                               double time_s, LayerUpdate& update, UpdateReport& report) {
  // The readings applied, once each (a buffer in both lists gives its observations twice), in gathering order.
  std::vector<const nav2::Nav2Observation*> seen;
  for (const auto& [i, obs] : applied) {
    if (std::find(seen.begin(), seen.end(), obs) != seen.end()) continue;
    seen.push_back(obs);
    Source& s = sources_[i];
    const auto it = s.reading_of.find(obs);
    if (it == s.reading_of.end()) continue;
    // The buffer's cloud, shared with its observation (an aliasing pointer keeps the observation alive).
    const auto held = std::find_if(s.buffer.observations().begin(), s.buffer.observations().end(),
                                   [&](const auto& k) { return k.get() == obs; });
    std::shared_ptr<const Eigen::Matrix3Xf> cloud;
    if (held != s.buffer.observations().end())
      cloud = std::shared_ptr<const Eigen::Matrix3Xf>(*held, &(*held)->cloud_W);
    update.applied_readings.push_back({s.sensor_index, s.source_index, it->second, std::move(cloud)});
    if (std::abs(it->second->time_s - time_s) <= kTimeEpsilon_s) continue;  // delivered for this cycle
    ++report.reapplied_readings;
    ++s.status.reapplied_readings;
    s.status.max_reapplied_age_s = std::max(s.status.max_reapplied_age_s, time_s - it->second->time_s);
  }
}

void Nav2Layer::update_costs(const nav2::Bounds& bounds, const std::vector<Eigen::Vector2d>& footprint_W) {
  // LayeredCostmap::updateMap: reset the master inside the bounds, then updateCosts.
  int x0 = 0, y0 = 0, xn = 0, yn = 0;
  nav2::world_to_map_enforce_bounds(grid_, bounds.min_x_m, bounds.min_y_m, x0, y0);
  nav2::world_to_map_enforce_bounds(grid_, bounds.max_x_m, bounds.max_y_m, xn, yn);
  x0 = std::max(0, x0), y0 = std::max(0, y0);
  xn = std::min(static_cast<int>(grid_.size_x_cells), xn + 1);
  yn = std::min(static_cast<int>(grid_.size_y_cells), yn + 1);
  if (xn >= x0 && yn >= y0) {
    if (!footprint_W.empty()) {  // setConvexPolygonCost(transformed_footprint_, FREE_SPACE)
      bool inside = true;
      for (const auto& p : footprint_W) {
        unsigned mx = 0, my = 0;
        inside = inside && nav2::world_to_map(grid_, p.x(), p.y(), mx, my);
      }
      if (inside)
        for (const auto& [ix, iy] : mapping::footprint_cells(
                 footprint_W, Eigen::Vector2d(grid_.origin_x_m, grid_.origin_y_m), grid_.resolution_m))
          if (ix >= 0 && iy >= 0 && ix < static_cast<int>(grid_.size_x_cells) &&
              iy < static_cast<int>(grid_.size_y_cells))
            grid_.costs[grid_.index(static_cast<unsigned>(ix), static_cast<unsigned>(iy))] = nav2::kFreeSpace;
    }
    master_->combine(grid_.costs, x0, y0, xn, yn, config_.nav2.combination_method);
  }
}

void Nav2Layer::record_cleared_keys(UpdateReport& report) {
  // What the cycle cleared, as the bench's voxels: those gone from the view that are still inside the window.
  view_stale_ = true;
  if (config_.type == LayerType::kNav2Voxel) {
    std::vector<VoxelKey> keys = marked_keys();
    const double r = grid_.resolution_m;
    const auto in_window = [&](const VoxelKey& k) {
      const double x = (k.x + 0.5) * r, y = (k.y + 0.5) * r;
      return x >= grid_.origin_x_m && y >= grid_.origin_y_m && x < grid_.origin_x_m + grid_.size_x_cells * r &&
             y < grid_.origin_y_m + grid_.size_y_cells * r;
    };
    for (const VoxelKey& k : last_keys_)
      if (!std::binary_search(keys.begin(), keys.end(), k) && in_window(k)) report.cleared_keys.push_back(k);
    last_keys_ = std::move(keys);
  }
}

void Nav2Layer::roll_to(double new_origin_x_m, double new_origin_y_m) {
  // Costmap2D::updateOrigin (VoxelLayer::updateOrigin also moves the voxel columns): whole cells, truncated.
  const double res = grid_.resolution_m;
  const int cell_ox = static_cast<int>((new_origin_x_m - grid_.origin_x_m) / res);
  const int cell_oy = static_cast<int>((new_origin_y_m - grid_.origin_y_m) / res);
  const double new_grid_ox = grid_.origin_x_m + cell_ox * res, new_grid_oy = grid_.origin_y_m + cell_oy * res;
  const int size_x = static_cast<int>(grid_.size_x_cells), size_y = static_cast<int>(grid_.size_y_cells);
  const int lower_left_x = std::min(std::max(cell_ox, 0), size_x),
            lower_left_y = std::min(std::max(cell_oy, 0), size_y);
  const int upper_right_x = std::min(std::max(cell_ox + size_x, 0), size_x);
  const int upper_right_y = std::min(std::max(cell_oy + size_y, 0), size_y);
  const int start_x = lower_left_x - cell_ox, start_y = lower_left_y - cell_oy;
  const bool voxels = config_.type == LayerType::kNav2Voxel;
  std::vector<std::uint8_t> costs(grid_.costs.size(),
                                  master_->config().track_unknown_space ? nav2::kNoInformation : nav2::kFreeSpace);
  std::vector<std::uint32_t> columns;
  if (voxels) columns.assign(voxel_grid_.columns().size(), nav2::kUnknownColumn);
  for (int y = lower_left_y; y < upper_right_y; ++y)
    for (int x = lower_left_x; x < upper_right_x; ++x) {
      const std::size_t from = static_cast<std::size_t>(y) * size_x + x;
      const std::size_t to =
          static_cast<std::size_t>(y - lower_left_y + start_y) * size_x + (x - lower_left_x + start_x);
      costs[to] = grid_.costs[from];
      if (voxels) columns[to] = voxel_grid_.columns()[from];
    }
  grid_.costs.swap(costs);
  if (voxels) voxel_grid_.columns().swap(columns);
  grid_.origin_x_m = new_grid_ox, grid_.origin_y_m = new_grid_oy;
  const Eigen::Vector2d& master_origin = master_->master().origin_m;
  if (std::abs(master_origin.x() - grid_.origin_x_m) > 1e-9 || std::abs(master_origin.y() - grid_.origin_y_m) > 1e-9)
    throw std::logic_error("Nav2Layer: the layer's grid and the master rolled apart");
}

bool Nav2Layer::current(double time_s) const {
  const std::int64_t now_ns = nav2::ros_ns_from_seconds(time_s);
  return std::all_of(sources_.begin(), sources_.end(), [&](const Source& s) { return s.buffer.is_current(now_ns); });
}

void Nav2Layer::reset(double time_s) {
  // navigation2 jazzy f4108e5 obstacle_layer.cpp reset() (voxel_layer.cpp's calls it, then resets its grid):
  // resetMaps() (every cell the default), resetBuffersLastUpdated() (the observations kept); current_ false and
  // was_reset_ are navigation::NavCostmap's. A source stale until now is recorded so before its clock
  // restarts.
  for (Source& s : sources_) {
    if (const auto span = stale_span(s.last_updated_s, time_s, s.status.expected_update_rate_s))
      s.status.stale.push_back(*span);
    s.last_updated_s = time_s;
    s.buffer.reset_last_updated(nav2::ros_ns_from_seconds(time_s));
  }
  grid_.costs.assign(grid_.costs.size(),
                     master_->config().track_unknown_space ? nav2::kNoInformation : nav2::kFreeSpace);
  voxel_grid_.reset();
  view_stale_ = true;
  master_->reset();
}

mapping::Costmap2D Nav2Layer::costmap() const {
  mapping::Costmap2D out;
  out.width = static_cast<int>(grid_.size_x_cells), out.height = static_cast<int>(grid_.size_y_cells);
  out.resolution_m = grid_.resolution_m;
  out.origin_m = Eigen::Vector2d(grid_.origin_x_m, grid_.origin_y_m);
  out.cells = grid_.costs;
  return out;
}

const mapping::VoxelMap& Nav2Layer::voxels() const {
  if (view_stale_) {
    std::vector<mapping::Voxel> all;
    for (const VoxelKey& k : last_keys_) all.push_back({k, 0.0});
    mapping::VoxelMap fresh(view_.config());
    fresh.set_voxels(all);
    view_ = std::move(fresh);
    view_stale_ = false;
  }
  return view_;
}

std::vector<SourceStatus> Nav2Layer::source_status(double until_s) const {
  std::vector<SourceStatus> all;
  for (const Source& s : sources_) {
    SourceStatus status = s.status;
    if (const auto span = stale_span(s.last_updated_s, until_s, status.expected_update_rate_s))
      status.stale.push_back(*span);
    all.push_back(std::move(status));
  }
  return all;
}

}  // namespace stvl::layer

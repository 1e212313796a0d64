#include "pipeline/pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <optional>
#include <set>
#include <unordered_set>
#include <sstream>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "common/splitmix.hpp"
#include "sensors/depth_renderer.hpp"
#include "mapping/footprint.hpp"

namespace stvl::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

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

// Camera 0 keeps the scenario's seed (its frames are what a one-camera run always had); the others get
// splitmix64 of seed and index, so that no two cameras share noise.
std::uint64_t camera_noise_seed(std::uint64_t seed, std::size_t index) {
  if (index == 0) return seed;
  return splitmix64_mix(seed + 0x9E3779B97F4A7C15ull * static_cast<std::uint64_t>(index));
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

bool upright(const sim::Simulator& sim) {
  const Eigen::Vector3d p = sim.T_world_base().translation();
  return sim.robot().tilt_rad() <= 0.5 && p.z() >= -0.5 && p.allFinite();
}

// A path the robot cannot reach (off the floor, 1e308 m away) would only end at the run's time limit.
void check_inside_world(const PipelineConfig& c, const sim::World& world) {
  const Eigen::AlignedBox2d extent = world.extent_xy();
  if (extent.isEmpty()) return;
  const auto describe = [](const Eigen::Vector2d& p) {
    std::ostringstream text;
    text << "(" << p.x() << ", " << p.y() << ")";
    return text.str();
  };
  const auto check = [&](const Eigen::Vector2d& p, const std::string& what) {
    if (extent.contains(p)) return;
    std::ostringstream text;
    text << what << " " << describe(p) << " m lies outside the world's extent, x " << extent.min().x() << " .. "
         << extent.max().x() << " m, y " << extent.min().y() << " .. " << extent.max().y() << " m (" << c.world_path << ")";
    throw std::invalid_argument(text.str());
  };
  check({c.start_pose.x_m, c.start_pose.y_m}, "robot.start");
  for (std::size_t i = 0; i < c.path.waypoints_W.size(); ++i)
    check(c.path.waypoints_W[i], "robot.waypoints[" + std::to_string(i) + "]");
}

}  // namespace

std::unique_ptr<sim::Simulator> make_simulator(const PipelineConfig& c) {
  sim::World world = sim::World::from_file(c.world_path);
  world.show_robot_geoms_to_cameras(c.robot_geoms_seen);
  auto sim = std::make_unique<sim::Simulator>(std::move(world), c.sim);
  sim->set_start_pose(c.start_pose);
  sim->set_path(c.path);
  if (!c.moving_bodies.empty()) sim->set_mocap_tracks(c.moving_bodies);
  return sim;
}

HeightBand marking_band(const PipelineConfig& config) {
  std::optional<HeightBand> band;
  for (const auto& camera : config.cameras)
    for (const auto& source : camera.sources) {
      if (!source.params.marking) continue;
      if (!band) band = HeightBand{source.params.min_obstacle_height_m, source.params.max_obstacle_height_m};
      band->min_m = std::min(band->min_m, source.params.min_obstacle_height_m);
      band->max_m = std::max(band->max_m, source.params.max_obstacle_height_m);
    }
  if (band) return *band;
  if (config.cameras.empty() || config.cameras.front().sources.empty()) return {};
  const auto& first = config.cameras.front().sources.front().params;
  return {first.min_obstacle_height_m, first.max_obstacle_height_m};
}

void validate_cameras(const PipelineConfig& config) {
  if (config.cameras.empty()) throw std::invalid_argument("pipeline: no camera");
  std::set<std::string> cameras, sources;
  for (const auto& c : config.cameras) {
    const std::string who = "camera '" + c.name + "'";
    if (c.name.empty()) throw std::invalid_argument("camera: empty name");
    if (!cameras.insert(c.name).second) throw std::invalid_argument(who + ": two cameras have this name");
    const auto rethrow = [&](const std::string& what, const auto& validate) {
      try {
        validate();
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(what + ": " + e.what());
      }
    };
    rethrow(who, [&] { c.intrinsics.validate(); });
    rethrow(who, [&] { c.noise.validate(); });
    rethrow(who, [&] { c.edge_filter.validate(); });
    const auto& m = c.mount;
    const double values[] = {m.forward_offset_m, m.lateral_offset_m, m.height_m, m.roll_rad, m.pitch_rad, m.yaw_rad};
    for (double v : values)
      if (!std::isfinite(v)) throw std::invalid_argument(who + ": mount values must be finite");
    if (!(m.height_m > 0.0))
      throw std::invalid_argument(who + ": mounted below the floor (height " + std::to_string(m.height_m) + " m)");
    if (Eigen::Vector3d(m.forward_offset_m, m.lateral_offset_m, m.height_m).norm() > 2.0)
      throw std::invalid_argument(who + ": mounted more than 2 m from base_link");
    if (c.sources.empty()) throw std::invalid_argument(who + ": feeds no observation source");
    for (std::size_t i = 0; i < c.outages.size(); ++i) {
      const Outage& o = c.outages[i];
      if (!(std::isfinite(o.from_s) && std::isfinite(o.to_s) && o.from_s >= 0.0 && o.from_s < o.to_s))
        throw std::invalid_argument(who + ": outage " + std::to_string(i) + " must be finite with 0 <= from_s < to_s");
      if (i > 0 && o.from_s < c.outages[i - 1].to_s)
        throw std::invalid_argument(who + ": outage " + std::to_string(i) + " overlaps or precedes the one before");
    }
    for (const auto& source : c.sources) {
      if (source.name.empty()) throw std::invalid_argument(who + ": a source has an empty name");
      if (!sources.insert(source.name).second)
        throw std::invalid_argument("observation source '" + source.name + "': the name is used twice");
      rethrow(who + ", source '" + source.name + "'", [&] { source.params.validate(); });
    }
  }
}

bool in_outage(const CameraConfig& camera, double time_s) {
  for (const auto& o : camera.outages)
    if (time_s >= o.from_s && time_s < o.to_s) return true;
  return false;
}

filter::FilterConfig decimation_config(filter::FilterConfig config) {
  config.passthrough_enabled = false;
  if (config.type == filter::FilterType::kPassthrough) config.type = filter::FilterType::kNone;
  return config;
}

struct Pipeline::Camera {
  Camera(const mjModel* model, const CameraConfig& c, std::uint64_t noise_seed)
      : config(c), renderer(model, c.intrinsics, c.gl_backend), noise(c.noise, c.intrinsics), noise_seed(noise_seed) {
    for (const auto& source : c.sources) {
      if (source.params.clearing && source.params.clear_on_no_return)
        no_return_range_m = std::max(no_return_range_m, source.params.max_z_m);
      buffers.emplace_back(source.params.observation_persistence_s, source.params.expected_update_rate_s);
      status.push_back({source.name, 0, source.params.expected_update_rate_s, {}, 0, 0.0, 0.0});
    }
    skip_outages();
  }
  CameraConfig config;
  double no_return_range_m = 0.0;  // > 0: the longest max_z of its clear_on_no_return sources
  std::vector<SourceBuffer> buffers;  // one per source
  std::vector<SourceStatus> status;   // one per source
  double last_frame_s = -1.0;         // < 0: none taken yet
  double last_reapplied_s = -1.0;     // the last update time its buffers were applied at another camera's frame
  std::size_t skipped_frames = 0;
  void skip_outages() {
    while (in_outage(config, next_time_s())) ++next_frame, ++skipped_frames;
  }
  // It has missed a frame (an outage): one was due after its last and by now_s, and none is pending at now_s
  // (a camera of a higher index with a frame at now_s takes it right after this one).
  bool overdue(double now_s) const {
    return last_frame_s >= 0.0 && last_frame_s + 1.0 / config.intrinsics.rate_hz <= now_s + 1e-9 &&
           next_time_s() > now_s + 1e-9;
  }
  sensors::DepthRenderer renderer;
  sensors::DepthNoise noise;
  std::uint64_t noise_seed;
  std::size_t next_frame = 0;
  // k * period, not k / rate: the frame times the bench has always used (they differ in the last bit).
  double next_time_s() const { return static_cast<double>(next_frame) * (1.0 / config.intrinsics.rate_hz); }
};

Pipeline::Pipeline(PipelineConfig config)
    : config_(std::move(config)),
      filter_(decimation_config(config_.filter)),
      passthrough_(config_.filter.passthrough_enabled || config_.filter.type == filter::FilterType::kPassthrough),
      map_(config_.map) {
  validate_cameras(config_);
  sim_ = make_simulator(config_);
  check_inside_world(config_, sim_->world());
  for (std::size_t i = 0; i < config_.cameras.size(); ++i) {
    const CameraConfig& c = config_.cameras[i];
    const Eigen::Vector3d p_base = sim::T_base_camera_link(c.mount).translation();
    const std::string geom = sim_->robot().geom_containing(p_base);
    if (!geom.empty())
      throw std::invalid_argument("camera '" + c.name + "': mounted inside the robot's body (geom '" + geom + "')");
    cameras_.push_back(std::make_unique<Camera>(sim_->world().model(), c, camera_noise_seed(config_.seed, i)));
    for (auto& status : cameras_.back()->status) status.camera_index = i;
  }
}

Pipeline::~Pipeline() = default;

std::vector<SourceStatus> Pipeline::source_status(double until_s) const {
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

std::size_t Pipeline::skipped_frames(std::size_t camera) const { return cameras_.at(camera)->skipped_frames; }

const char* Pipeline::gl_backend() const { return cameras_.front()->renderer.backend_name(); }
const char* Pipeline::filter_device() const { return filter_.device_used(); }

mapping::CostmapOptions Pipeline::costmap_options() const {
  mapping::CostmapOptions options;
  const HeightBand band = marking_band(config_);
  options.min_obstacle_height_m = band.min_m;
  options.max_obstacle_height_m = band.max_m;
  if (config_.map.update_footprint_enabled)  // STVL: at the robot's pose of the last update
    options.free_polygon_W = mapping::footprint_in_world(config_.map.footprint_B, sim_->T_world_base());
  return options;
}

mapping::Costmap2D Pipeline::costmap() const { return map_.project_costmap(costmap_options()); }

double Pipeline::next_time_s() const {
  double t = cameras_.front()->next_time_s();
  for (const auto& c : cameras_) t = std::min(t, c->next_time_s());
  return t;
}

const FrameResult& Pipeline::step(const BeforeMapUpdate& before_map_update) {
  std::size_t index = 0;
  for (std::size_t c = 1; c < cameras_.size(); ++c)
    if (cameras_[c]->next_time_s() < cameras_[index]->next_time_s()) index = c;
  Camera& camera = *cameras_[index];
  FrameResult& f = frame_;
  f.camera_index = index;
  f.camera = camera.config.name;
  f.frame_index = camera.next_frame;
  f.time_s = camera.next_time_s();
  ++camera.next_frame;
  camera.skip_outages();
  f.times = {};

  sim_->run_until(f.time_s);
  f.T_world_base = sim_->T_world_base();
  f.T_odom_base = sim_->T_odom_base();
  f.T_map_odom = sim_->T_map_odom();
  f.T_world_camera = sim_->T_world_camera(camera.config.mount);
  f.odom_v_mps = sim_->odometry().v_mps();
  f.odom_omega_radps = sim_->odometry().omega_radps();
  f.robot_upright = upright(*sim_);
  if (!f.robot_upright) return f;

  const auto& intrinsics = camera.config.intrinsics;
  auto start = Clock::now();
  f.clean_depth = camera.renderer.render(sim_->world().model(), sim_->world().data(), f.T_world_camera);
  f.times.render_ms = ms_since(start);

  start = Clock::now();
  f.depth = f.clean_depth;
  camera.noise.apply(f.depth, camera.noise_seed, f.frame_index);
  f.times.noise_ms = ms_since(start);

  start = Clock::now();
  const sensors::DepthImage* cloud_depth = &f.depth;
  f.edge_dropped_pixels = 0;
  if (camera.config.edge_filter.enabled) {
    f.edge_dropped_pixels = sensors::filter_depth_edges(camera.config.edge_filter, f.depth, f.edge_filtered_depth);
    cloud_depth = &f.edge_filtered_depth;
  } else {
    f.edge_filtered_depth = {};
  }
  f.point_count = sensors::depth_to_cloud(*cloud_depth, intrinsics, f.points_C);
  transform(f.T_world_camera, f.points_C, f.point_count, f.cloud_W);
  f.times.cloud_ms = ms_since(start);

  start = Clock::now();
  f.decimated_W = filter_.apply(f.cloud_W);
  f.marking_W = passthrough_ ? filter::passthrough(f.decimated_W, config_.filter.passthrough) : f.decimated_W;
  f.times.filter_ms = ms_since(start);

  if (before_map_update) before_map_update(f, map_);

  start = Clock::now();
  const double cpu_start_ms = process_cpu_ms();
  f.no_return_W.resize(3, 0);
  if (camera.no_return_range_m > 0.0)
    no_return_points(f.depth, intrinsics, f.T_world_camera, camera.no_return_range_m, config_.map.voxel_size_m,
                     f.no_return_W);
  auto reading = std::make_shared<SourceReading>();
  reading->time_s = f.time_s;
  reading->T_world_camera = f.T_world_camera;
  reading->decimated_W = f.decimated_W;
  reading->marking_W = f.marking_W;
  reading->no_return_W = f.no_return_W;
  for (std::size_t s = 0; s < camera.buffers.size(); ++s) {
    SourceBuffer& buffer = camera.buffers[s];
    if (const auto span = stale_span(buffer.last_updated_s(), f.time_s, buffer.expected_update_rate_s()))
      camera.status[s].stale.push_back(*span);
    buffer.receive(reading);
  }
  camera.last_frame_s = f.time_s;
  // STVL's update: the readings of every buffer it applies, clearing first, then marking, all at this time.
  std::vector<mapping::ClearingObservation> clearing;
  std::vector<std::pair<const SourceReading*, const mapping::ObservationSource*>> marking;
  f.reapplied_readings = 0;
  for (auto& other : cameras_) {
    Camera& c = *other;
    // Another camera's buffer once per update time: cameras that share a frame time make one STVL update.
    if (&c != &camera && (!c.overdue(f.time_s) || c.last_reapplied_s >= f.time_s - 1e-9)) continue;
    if (&c != &camera) c.last_reapplied_s = f.time_s;
    const Eigen::Vector3d centre_now = sim_->T_world_camera(c.config.mount).translation();
    for (std::size_t s = 0; s < c.buffers.size(); ++s) {
      const auto& params = c.config.sources[s].params;
      if (&c != &camera && params.drop_when_not_current && !c.buffers[s].current(f.time_s)) continue;
      for (const auto& r : c.buffers[s].readings()) {
        if (params.clearing) clearing.push_back({r->T_world_camera, params, &r->decimated_W, &r->no_return_W});
        if (params.marking) marking.emplace_back(r.get(), &params);
        if (r.get() == reading.get()) continue;
        ++f.reapplied_readings;
        SourceStatus& status = c.status[s];
        ++status.reapplied_readings;
        status.max_reapplied_age_s = std::max(status.max_reapplied_age_s, f.time_s - r->time_s);
        status.reapplied_max_distance_m = std::max(status.reapplied_max_distance_m,
                                                   (r->T_world_camera.translation() - centre_now).norm());
      }
    }
  }
  f.cleared_keys.clear();
  map_.clear(clearing, f.time_s, &f.cleared_keys);
  f.times.clear_ms = ms_since(start);
  start = Clock::now();
  for (const auto& [r, params] : marking) map_.mark(r->marking_W, r->T_world_camera, *params, f.time_s);
  f.footprint_cleared = 0;
  if (config_.map.footprint_clearing_height_m > 0.0) {
    // Ours: the robot's own voxels inside its footprint, from the floor up to the height given, after marking.
    const double s = config_.map.voxel_size_m;
    const auto polygon_W = mapping::footprint_in_world(config_.map.footprint_B, f.T_world_base);
    const int top = static_cast<int>(std::ceil(config_.map.footprint_clearing_height_m / s)) - 1;
    std::vector<VoxelKey> keys;
    for (const auto& [ix, iy] : mapping::footprint_cells(polygon_W, Eigen::Vector2d::Zero(), s))
      for (int iz = 0; iz <= top; ++iz) keys.push_back({ix, iy, iz});
    f.footprint_cleared = map_.erase(keys, &f.cleared_keys);
  }
  f.times.mark_ms = ms_since(start);
  f.times.map_cpu_ms = process_cpu_ms() - cpu_start_ms;
  return f;
}

}  // namespace stvl::pipeline

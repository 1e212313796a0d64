#include "pipeline/pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <sstream>
#include <stdexcept>

#include "sensors/depth_renderer.hpp"

namespace stvl::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

Eigen::Matrix3Xf transform(const Eigen::Isometry3d& T, const Eigen::Matrix3Xf& points, Eigen::Index count) {
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  return (R * points.leftCols(count)).colwise() + t;
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
  auto sim = std::make_unique<sim::Simulator>(sim::World::from_file(c.world_path), c.sim);
  sim->set_start_pose(c.start_pose);
  sim->set_path(c.path);
  if (!c.moving_bodies.empty()) sim->set_mocap_tracks(c.moving_bodies);
  return sim;
}

filter::FilterConfig decimation_config(filter::FilterConfig config) {
  config.passthrough_enabled = false;
  if (config.type == filter::FilterType::kPassthrough) config.type = filter::FilterType::kNone;
  return config;
}

struct Pipeline::Camera {
  Camera(const mjModel* model, const CameraConfig& c)
      : config(c), renderer(model, c.intrinsics, c.gl_backend), noise(c.noise, c.intrinsics) {}
  CameraConfig config;
  sensors::DepthRenderer renderer;
  sensors::DepthNoise noise;
  std::size_t next_frame = 0;
  // k * period, not k / rate: the frame times the bench has always used (they differ in the last bit).
  double next_time_s() const { return static_cast<double>(next_frame) * (1.0 / config.intrinsics.rate_hz); }
};

Pipeline::Pipeline(PipelineConfig config)
    : config_(std::move(config)),
      filter_(decimation_config(config_.filter)),
      passthrough_(config_.filter.passthrough_enabled || config_.filter.type == filter::FilterType::kPassthrough),
      map_(config_.map) {
  if (config_.cameras.empty()) throw std::invalid_argument("pipeline: no camera");
  if (config_.cameras.size() > 1)
    throw std::invalid_argument("pipeline: " + std::to_string(config_.cameras.size()) +
                                " cameras given; one camera per robot is supported so far");
  for (const auto& c : config_.cameras) {
    c.intrinsics.validate();
    c.source.validate();
  }
  sim_ = make_simulator(config_);
  check_inside_world(config_, sim_->world());
  for (const auto& c : config_.cameras) cameras_.push_back(std::make_unique<Camera>(sim_->world().model(), c));
}

Pipeline::~Pipeline() = default;

const char* Pipeline::gl_backend() const { return cameras_.front()->renderer.backend_name(); }
const char* Pipeline::filter_device() const { return filter_.device_used(); }

mapping::CostmapOptions Pipeline::costmap_options() const {
  mapping::CostmapOptions options;
  options.min_obstacle_height_m = config_.cameras.front().source.min_obstacle_height_m;
  options.max_obstacle_height_m = config_.cameras.front().source.max_obstacle_height_m;
  for (const auto& c : config_.cameras) {
    options.min_obstacle_height_m = std::min(options.min_obstacle_height_m, c.source.min_obstacle_height_m);
    options.max_obstacle_height_m = std::max(options.max_obstacle_height_m, c.source.max_obstacle_height_m);
  }
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
  f.times = {};

  sim_->run_until(f.time_s);
  f.T_world_base = sim_->T_world_base();
  f.T_odom_base = sim_->T_odom_base();
  f.T_map_odom = sim_->T_map_odom();
  f.T_world_camera = sim_->T_world_camera();
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
  camera.noise.apply(f.depth, config_.seed, f.frame_index);
  f.times.noise_ms = ms_since(start);

  start = Clock::now();
  f.point_count = sensors::depth_to_cloud(f.depth, intrinsics, f.points_C);
  f.cloud_W = transform(f.T_world_camera, f.points_C, f.point_count);
  f.times.cloud_ms = ms_since(start);

  start = Clock::now();
  f.decimated_W = filter_.apply(f.cloud_W);
  f.marking_W = passthrough_ ? filter::passthrough(f.decimated_W, config_.filter.passthrough) : f.decimated_W;
  f.times.filter_ms = ms_since(start);

  if (before_map_update) before_map_update(f, map_);

  start = Clock::now();
  const mapping::ClearingObservation observation{f.T_world_camera, camera.config.source, &f.decimated_W};
  map_.clear({observation}, f.time_s);
  f.times.clear_ms = ms_since(start);
  start = Clock::now();
  map_.mark(f.marking_W, f.T_world_camera, camera.config.source, f.time_s);
  f.times.mark_ms = ms_since(start);
  return f;
}

}  // namespace stvl::pipeline

#include "pipeline/pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "common/splitmix.hpp"
#include "common/stopwatch.hpp"
#include "pipeline/sensing.hpp"
#include "sensors/depth_renderer.hpp"
#include "sim/urdf_robot.hpp"

namespace stvl::pipeline {
namespace {

// Camera 0 keeps the scenario's seed (its frames are what a one-camera run always had); the others get
// splitmix64 of seed and index, so that no two cameras share noise.
std::uint64_t camera_noise_seed(std::uint64_t seed, std::size_t index) {
  if (index == 0) return seed;
  return splitmix64_mix(seed + 0x9E3779B97F4A7C15ull * static_cast<std::uint64_t>(index));
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
         << extent.max().x() << " m, y " << extent.min().y() << " .. " << extent.max().y() << " m (" << c.world_path
         << ")";
    throw std::invalid_argument(text.str());
  };
  check({c.start_pose.x_m, c.start_pose.y_m}, "robot.start");
  for (std::size_t i = 0; i < c.path.waypoints_W.size(); ++i)
    check(c.path.waypoints_W[i], "robot.waypoints[" + std::to_string(i) + "]");
}

}  // namespace

sim::World load_world(const PipelineConfig& c) {
  if (!c.world_xml.empty()) {  // a world built in memory (nav2_map), with the URDF robot in place of robot.xml
    std::vector<sim::VirtualFile> robot;
    if (c.urdf_robot) robot.push_back({"robot.xml", c.urdf_robot->mjcf});
    try {
      return sim::World::from_string(c.world_xml, c.world_include_dir, robot);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error("the world built from " + c.world_path + ": " + e.what());
    }
  }
  return c.urdf_robot ? sim::load_world_with_robot(c.world_path, *c.urdf_robot) : sim::World::from_file(c.world_path);
}

std::unique_ptr<sim::Simulator> make_simulator(const PipelineConfig& c) {
  sim::World world = load_world(c);
  world.show_robot_geoms_to_cameras(c.robot_geoms_seen);
  auto sim = std::make_unique<sim::Simulator>(std::move(world), c.sim);
  sim->set_start_pose(c.start_pose);
  if (!c.path.waypoints_W.empty()) sim->set_path(c.path);  // none in closed loop: navigation/ drives
  if (!c.moving_bodies.empty()) sim->set_mocap_tracks(c.moving_bodies);
  return sim;
}

mapping::ZReference band_frame(const PipelineConfig& config) {
  for (const auto& camera : config.cameras)
    for (const auto& source : camera.sources)
      if (source.params.marking && source.params.height_band) return source.params.z_reference;
  return mapping::ZReference::kGlobal;
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
      const auto& p = source.params;
      if (p.marking && p.height_band && p.z_reference != band_frame(config))
        throw std::invalid_argument(who + ", source '" + source.name + "': z_reference_frame " +
                                    mapping::to_string(p.z_reference) + " differs from the other marking sources' " +
                                    mapping::to_string(band_frame(config)) +
                                    "; the bench filters each cloud in one frame");
    }
  }
}

bool PipelineConfig::timing_enabled() const {
  for (const auto& c : cameras)
    if (c.timing.enabled()) return true;
  return tf.odom_latency_s > 0.0 || sim.localization.enabled;
}

bool in_outage(const CameraConfig& camera, double time_s) {
  for (const auto& o : camera.outages)
    if (time_s >= o.from_s && time_s < o.to_s) return true;
  return false;
}

// Each camera as a sensor of the layer: its name, rate and sources.
static std::vector<layer::SensorConfig> layer_sensors(const PipelineConfig& config) {
  std::vector<layer::SensorConfig> sensors;
  for (const auto& c : config.cameras) sensors.push_back({c.name, c.intrinsics.rate_hz, c.sources});
  return sensors;
}

layer::LayerConfig layer_config(const PipelineConfig& config) {
  return {config.layer_type, config.map, config.nav2_layer, config.nav2_costmap, layer_sensors(config)};
}

layer::HeightBand marking_band(const PipelineConfig& config) { return layer::marking_band(layer_sensors(config)); }

filter::FilterConfig decimation_config(filter::FilterConfig config) {
  config.passthrough_enabled = false;
  if (config.type == filter::FilterType::kPassthrough) config.type = filter::FilterType::kNone;
  return config;
}

struct Pipeline::Camera {
  Camera(const mjModel* model, const CameraConfig& c, std::uint64_t noise_seed)
      : config(c), renderer(model, c.intrinsics, c.gl_backend), noise(c.noise, c.intrinsics), noise_seed(noise_seed) {
    skip_outages();
  }
  CameraConfig config;
  std::size_t skipped_frames = 0;
  void skip_outages() {
    while (in_outage(config, next_time_s())) ++next_frame, ++skipped_frames;
  }
  sensors::DepthRenderer renderer;
  sensors::DepthNoise noise;
  std::uint64_t noise_seed;
  std::size_t next_frame = 0;
  // k * period, not k / rate: the frame times the bench has always used (they differ in the last bit).
  double next_time_s() const { return static_cast<double>(next_frame) * (1.0 / config.intrinsics.rate_hz); }
  // The renderer holds (or, with `drawing`, is drawing) the image of this camera's next frame, at drawn_at_s:
  // drawn by an earlier step() of the same instant. `drawing` is the last member: waited for before the renderer goes.
  bool drawn = false;
  double drawn_at_s = 0;
  std::future<void> drawing;
};

Pipeline::Pipeline(PipelineConfig config) : config_(std::move(config)) {
  validate_cameras(config_);
  sim_ = make_simulator(config_);
  check_inside_world(config_, sim_->world());
  for (std::size_t i = 0; i < config_.cameras.size(); ++i) {
    const CameraConfig& c = config_.cameras[i];
    const Eigen::Vector3d p_base = sim::T_base_camera_link(c.mount).translation();
    // A camera at a URDF link may sit inside that link's own housing.
    const int own_body = c.frame.empty() ? -1 : mj_name2id(sim_->world().model(), mjOBJ_BODY, c.frame.c_str());
    const std::string geom = sim_->robot().geom_containing(p_base, own_body);
    if (!geom.empty())
      throw std::invalid_argument("camera '" + c.name + "': mounted inside the robot's body (geom '" + geom + "')");
    cameras_.push_back(std::make_unique<Camera>(sim_->world().model(), c, camera_noise_seed(config_.seed, i)));
  }
  sensing_ = std::make_unique<Sensing>(config_);
}

Pipeline::~Pipeline() = default;

void Pipeline::set_world_snapshots(bool on) {
  for (auto& snapshot : snapshots_) snapshot = on ? std::make_unique<sim::World>(sim_->world().copy()) : nullptr;
}

void Pipeline::release_gl_contexts() {
  for (auto& camera : cameras_) camera->renderer.release_context();
}

std::size_t Pipeline::skipped_frames(std::size_t camera) const { return cameras_.at(camera)->skipped_frames; }

const char* Pipeline::gl_backend() const { return cameras_.front()->renderer.backend_name(); }
const char* Pipeline::filter_device() const { return sensing_->filter_device(); }

double Pipeline::next_time_s() const {
  double t = cameras_.front()->next_time_s();
  for (const auto& c : cameras_) t = std::min(t, c->next_time_s());
  return t;
}

bool Pipeline::draw_ahead(std::size_t index, const Eigen::Isometry3d& T_world_camera) {
  if (!draw_ahead_) return false;
  Camera& camera = *cameras_[index];
  std::vector<std::size_t> others;
  const double now_s = frames_[current_].time_s;
  for (std::size_t c = 0; c < cameras_.size(); ++c)
    if (c != index && !cameras_[c]->drawn && cameras_[c]->next_time_s() == now_s) others.push_back(c);
  if (others.empty()) return false;
  // The same instant: the steps up to those cameras' frames do not move the simulator, so their images now are
  // the ones they would render then. Scenes are taken here (MuJoCo reads mjData on this thread), GL work on threads.
  const mjModel* model = sim_->world().model();
  mjData* data = sim_->world().data();
  for (std::size_t c : others) {
    Camera& other = *cameras_[c];
    other.renderer.prepare(model, data, sim_->T_world_camera(other.config.mount));
    other.renderer.release_context();  // in case this thread holds it: another thread takes it now
    other.drawn = true, other.drawn_at_s = now_s;
    other.drawing = std::async(std::launch::async, [&renderer = other.renderer] {
      renderer.draw();
      renderer.release_context();
    });
  }
  camera.renderer.render(model, data, T_world_camera);  // here, while the others draw
  return true;
}

Frame& Pipeline::capture() {
  std::size_t index = 0;
  for (std::size_t c = 1; c < cameras_.size(); ++c)
    if (cameras_[c]->next_time_s() < cameras_[index]->next_time_s()) index = c;
  Camera& camera = *cameras_[index];
  current_ = (current_ + 1) % kFramesInTurn;
  Frame& f = frames_[current_];
  f.camera_index = index;
  f.camera = camera.config.name;
  f.frame_index = camera.next_frame;
  f.time_s = f.stamp_s = camera.next_time_s();
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
  f.skipped_frames.resize(cameras_.size());
  for (std::size_t c = 0; c < cameras_.size(); ++c) f.skipped_frames[c] = cameras_[c]->skipped_frames;
  f.path_finished = sim_->path_finished();
  f.laps_completed = sim_->laps_completed();
  if (snapshots_[current_]) {
    snapshots_[current_]->copy_state_from(sim_->world());
    f.world = snapshots_[current_].get();
  } else {
    f.world = &sim_->world();
  }
  if (!f.robot_upright) return f;

  auto start = SteadyClock::now();
  if (camera.drawn) {
    camera.drawn = false;
    if (camera.drawn_at_s != f.time_s) throw std::logic_error("Pipeline::step: a camera was drawn for another time");
    if (camera.drawing.valid()) camera.drawing.get();  // rethrows the draw's exception
  } else if (!draw_ahead(index, f.T_world_camera)) {
    camera.renderer.render(sim_->world().model(), sim_->world().data(), f.T_world_camera);
  }
  f.clean_depth = camera.renderer.image();
  f.times.render_ms = ms_since(start);
  f.cameras_now.resize(cameras_.size());
  for (std::size_t c = 0; c < cameras_.size(); ++c)
    f.cameras_now[c] = {sim_->T_world_camera(cameras_[c]->config.mount), cameras_[c]->next_time_s()};
  return f;
}

Frame& Pipeline::add_noise(Frame& f) {
  if (!f.robot_upright) return f;
  Camera& camera = *cameras_.at(f.camera_index);
  const auto start = SteadyClock::now();
  camera.noise.apply(f.clean_depth, f.depth, camera.noise_seed, f.frame_index);  // clean -> noisy, no copy
  f.times.noise_ms = ms_since(start);
  return f;
}

const Frame& Pipeline::sense_only(Frame& f) {
  if (f.robot_upright) sensing_->sense(f);
  return f;
}

}  // namespace stvl::pipeline

#pragma once
// The simulated side of the bench: the simulator, the robot's depth cameras (render, noise, depth to cloud) and the
// decimation filter, built from one plain config. Each step() advances to the next camera frame and senses it, up
// to the frame's observation for the layer (layer/); the frame loop (run/) updates the layer and evaluates:
//
//   stvl::pipeline::Pipeline pipeline(config);
//   stvl::layer::StvlLayer layer(stvl::pipeline::layer_config(config));
//   while (pipeline.next_time_s() <= duration_s) {
//     const stvl::pipeline::Frame& frame = pipeline.step();
//     if (!frame.robot_upright) break;
//     layer.update(frame.observation, frame.cameras_now, report);
//   }
//
// Frames: camera c takes frame k at k / rate_hz (its intrinsics' rate); step() takes the earliest pending
// frame of any camera (ties: the lower camera index), so cameras at different rates interleave in simulated
// time. Frames inside a camera's outages are not taken at all.
#include <array>
#include <memory>

#include "pipeline/config.hpp"
#include "pipeline/frame.hpp"
#include "sim/simulator.hpp"

namespace stvl::pipeline {

class Sensing;

class Pipeline {
 public:
  // Throws std::invalid_argument for a bad config or world, std::runtime_error when no GL context can be made
  // or a CUDA filter was required without a GPU.
  explicit Pipeline(PipelineConfig config);
  // Frees the simulator, the cameras' renderers, the filter and the map; not copyable.
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  // Simulated time of the frame the next step() takes.
  double next_time_s() const;
  // Frames capture() takes in turn: one stays valid through the next kFramesInTurn - 1 captures.
  static constexpr std::size_t kFramesInTurn = 3;
  // Runs the next frame up to its observation: sense(capture()). The result is owned by the pipeline and stays
  // valid through the next two captures (kFramesInTurn frames take turns), so that a caller may use it while the
  // next ones are made on other threads.
  const Frame& step() { return sense(capture()); }
  // The first half of step(): the simulator up to the next frame, its poses, the world's snapshot, where every
  // camera stands, and the noise-free image (nothing more for a robot that fell: robot_upright false).
  Frame& capture();
  // The second half, for a frame capture() gave: the camera's noise, then Sensing (cloud, decimation, band). Touches
  // nothing capture() does, so frame k may be sensed on one thread while frame k + 1 is captured on another.
  const Frame& sense(Frame& frame) { return sense_only(add_noise(frame)); }
  // sense()'s first part: the camera's noise, frame.depth from frame.clean_depth (times.noise_ms).
  Frame& add_noise(Frame& frame);
  // sense()'s second part: Sensing, from frame.depth to the observation.
  const Frame& sense_only(Frame& frame);
  // On: each capture() copies the simulated world into a snapshot of the frame's own (Frame::world), which the
  // next two captures leave alone; off (default): Frame::world is the live world, which the next capture() moves on.
  void set_world_snapshots(bool on);
  // Releases the cameras' GL contexts from the calling thread, so that capture() may run on another one.
  void release_gl_contexts();

  const PipelineConfig& config() const { return config_; }   // as given to the constructor
  const sim::Simulator& simulator() const { return *sim_; }  // the world and robot it steps
  // Closed loop: the simulator's wheels driven by `controller` every period_s (sim::Simulator::set_controller).
  void set_controller(sim::Simulator::TwistController controller, double period_s) {
    sim_->set_controller(std::move(controller), period_s);
  }
  // Runs the simulator up to time_s without taking a frame (monotonic: an earlier time does nothing); the frames
  // after it are those it would have taken anyway (the simulator steps whole timesteps either way).
  void run_until(double time_s) { sim_->run_until(time_s); }
  // Frames of camera `camera` not taken because they fell in one of its outages.
  std::size_t skipped_frames(std::size_t camera) const;
  // Cameras that take a frame at the same instant (same simulated state) render together (default on): the first
  // step() of that instant starts the others' GL drawing on threads of their own, which runs beside this frame's
  // noise, cloud, filter and map; their own step() then waits for it (its render_ms is that wait). The images are
  // those of rendering each at its own step() (tests/pipeline checks it); off: one after another.
  void set_draw_ahead(bool on) { draw_ahead_ = on; }
  const char* gl_backend() const;     // "egl" or "osmesa" (the first camera's)
  const char* filter_device() const;  // "cpu" or "cuda"

 private:
  struct Camera;
  PipelineConfig config_;
  std::unique_ptr<sim::Simulator> sim_;
  std::vector<std::unique_ptr<Camera>> cameras_;
  std::unique_ptr<Sensing> sensing_;         // edge filter, cloud, decimation
  std::array<Frame, kFramesInTurn> frames_;  // frames_[current_] is the latest
  std::size_t current_ = 0;
  // With set_world_snapshots(true): each frame's world.
  std::array<std::unique_ptr<sim::World>, kFramesInTurn> snapshots_;
  bool draw_ahead_ = true;
  // Renders camera `index`'s frame with the other cameras of this instant; false (nothing done) when none.
  bool draw_ahead(std::size_t index, const Eigen::Isometry3d& T_world_camera);
};

// The config's world with its robot: the file world_path, or world_xml when set (a scenario's nav2_map); with
// robot.xml, or the URDF robot in its place.
sim::World load_world(const PipelineConfig& config);

// The config's world with the robot at its start pose, on its path, and the moving bodies scripted (what the
// pipeline steps; the render command and benchmarks use it alone).
std::unique_ptr<sim::Simulator> make_simulator(const PipelineConfig& config);
}  // namespace stvl::pipeline

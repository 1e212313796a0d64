#pragma once
// The frame loop of the bench: the simulator, the robot's depth cameras (render, noise, depth to cloud), the
// decimation filter and the STVL map, built from one plain config. Each step() advances to the next camera
// frame and runs it through every stage:
//
//   stvl::pipeline::Pipeline pipeline(config);
//   while (pipeline.next_time_s() <= duration_s) {
//     const stvl::pipeline::FrameResult& frame = pipeline.step();
//     if (!frame.robot_upright) break;
//     ...  // evaluate, write outputs
//   }
//
// Frames: camera c takes frame k at k / rate_hz (its intrinsics' rate); step() takes the earliest pending
// frame of any camera (ties: the lower camera index), so cameras at different rates interleave in simulated
// time. A frame is cleared then marked into the map (STVL's order): the camera's clearing sources clear with
// the whole decimated cloud (so ray-cast clearing also sees the floor behind a moved obstacle), then its
// marking sources mark the decimated cloud inside the passthrough band, as STVL applies its passthrough
// before marking.
// Sources keep STVL's measurement buffers (source_buffer.hpp): a frame's update applies its camera's buffered
// readings (the frame's, plus older ones under observation_persistence) and, as STVL applies every buffer at
// every update, the buffers of cameras that have missed a frame (an outage): their last readings, at the pose
// they were taken from, cleared and marked again at this time, once per distinct update time (cameras sharing a
// frame time make one STVL update). A camera that has not missed a frame is left to its own next frame (STVL at
// an update rate equal to the cameras'). Frames inside a camera's outages are not taken at all.
#include <functional>
#include <memory>

#include "mapping/costmap.hpp"
#include "mapping/voxel_map.hpp"
#include "pipeline/frame.hpp"
#include "sim/simulator.hpp"

namespace stvl::pipeline {

class MapStages;

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
  // Called inside step() after sensing and filtering, before the map's update, with the map as the previous
  // frame left it (the evaluation needs that moment for clearing latency).
  using BeforeMapUpdate = std::function<void(const FrameResult& frame, const mapping::VoxelMap& map)>;
  // Runs the next frame. The result is owned by the pipeline and overwritten by the next step().
  const FrameResult& step(const BeforeMapUpdate& before_map_update = {});

  const PipelineConfig& config() const { return config_; }  // as given to the constructor
  const sim::Simulator& simulator() const { return *sim_; }  // the world and robot it steps
  const mapping::VoxelMap& map() const;  // as the last step() left it
  // With config.nav2_costmap: nav2's master costmap after the last update (null otherwise), and its ghosts.
  const mapping::Nav2Costmap* nav2_costmap() const;
  const Nav2Ghosts& nav2_ghosts() const;
  // The map's costmap at its voxel size over the occupied extent (1 x 1 when empty), counting every voxel of a
  // column (STVL's) or, with map.costmap_band marking_band (ours), those inside the marking sources' height band;
  // with map.update_footprint_enabled, the footprint's cells at the robot's current pose are free (STVL's
  // footprint clearing).
  mapping::Costmap2D costmap() const;
  // The options costmap() uses: costmap_options() of map_stages.hpp at the robot's current true pose.
  mapping::CostmapOptions costmap_options() const;
  // Every source's status (cameras in order, their sources in order), spans of staleness closed at until_s.
  std::vector<SourceStatus> source_status(double until_s) const;
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
  std::unique_ptr<MapStages> stages_;  // the filter, the sources' buffers and the map
  FrameResult frame_;
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

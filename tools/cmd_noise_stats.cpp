// stvl-bench noise-stats --real RECORDING [--out FILE.json] [--figures DIR]: a real depth camera (two frames of a
// static camera) against the simulated D435 of a comparable scene (a wall corner with an object in front, at the
// real frames' depths, rendered with the real frames' intrinsics), before (the default noise model) and after (its
// stereo occlusion on and 95 % of the disparity noise correlated): invalid pixels, edge bands, holes at
// discontinuities, plane-fit RMS and temporal sigma against Intel's formula.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>

#include <mujoco/mujoco.h>

#include "analysis/noise_stats.hpp"
#include "common/atomic_file.hpp"
#include "recording/recording.hpp"
#include "sensors/depth_noise.hpp"
#include "sensors/depth_renderer.hpp"
#include "tools/command.hpp"

#include <unistd.h>

namespace stvl::tools {
using namespace stvl::analysis;
namespace {

struct NoiseStatsCommandOptions {
  std::string real;
  std::string out;
  std::string figures;
  std::string gl = "auto";
  std::uint64_t seed = 1;
};

// Camera at (0, 0, 1) m looking along +x; world y is the image's left. A wall facing the camera at 1.75 m on the
// left half (the real frame's 1.6 to 1.8 m), a recess at 2.6 m through the corner (2.2 to 3 m), a side wall on the
// right running from 1.25 m to 0.39 m at the right edge (1.2 m to 0.39 m), an object 1.35 m away standing on the
// floor left of the centre (the bag, 1.36 to 1.42 m).
const char* kCornerScene = R"(
<mujoco>
  <worldbody>
    <geom type="box" size="4 4 0.01" pos="2 0 -0.01"/>
    <geom type="box" size="0.05 1.2 1.5" pos="1.80 1.2 1.0"/>
    <geom type="box" size="0.05 0.6 1.5" pos="2.65 -0.3 1.0"/>
    <geom type="box" size="0.44 0.02 1.5" pos="0.82 -0.23 1.0" euler="0 0 11.8"/>
    <geom type="box" size="0.1 0.14 0.425" pos="1.45 0.16 0.425"/>
  </worldbody>
</mujoco>)";

struct Scene {
  mjModel* model = nullptr;
  mjData* data = nullptr;
  Scene() {
    const auto path =
        std::filesystem::temp_directory_path() / ("stvl_noise_stats_" + std::to_string(::getpid()) + ".xml");
    std::ofstream(path) << kCornerScene;
    char error[1000] = "";
    model = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
    std::filesystem::remove(path);
    if (!model) throw std::runtime_error(std::string("noise-stats scene: ") + error);
    data = mj_makeData(model);
    mj_forward(model, data);
  }
  ~Scene() {
    mj_deleteData(data);
    mj_deleteModel(model);
  }
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;
};

// The first two frames of the real recording (a static camera) and what the recording says of itself.
struct RealFrames {
  recording::RecordingInfo info;
  sensors::DepthImage depth[2];
};

RealFrames read_real_frames(const std::string& path) {
  recording::RecordingOptions recording_options;
  recording_options.min_range_m = 0.1;
  const auto recording = recording::open_recording(path, recording_options);
  RealFrames real;
  recording::RecordedFrame frame;
  for (int k = 0; k < 2; ++k) {
    if (!recording->next(frame))
      throw std::invalid_argument(path + ": noise-stats needs two frames of a static camera, the recording has " +
                                  std::to_string(k));
    real.depth[k] = frame.depth;
  }
  real.info = recording->info();
  const sensors::CameraIntrinsics& real_k = real.info.intrinsics;
  if (!real_k.square_pixels())
    throw std::invalid_argument(path + ": fx " + std::to_string(real_k.fx) + " != fy " + std::to_string(real_k.fy) +
                                ": the simulated camera renders square pixels only");
  return real;
}

// The simulated D435 with the real camera's geometry and the preset's range.
sensors::CameraIntrinsics simulated_intrinsics(const sensors::CameraIntrinsics& real_k) {
  sensors::CameraIntrinsics sim_k = sensors::CameraIntrinsics::d435_640x480();
  sim_k.width = real_k.width;
  sim_k.height = real_k.height;
  sim_k.fx = real_k.fx;
  sim_k.fy = real_k.fy;
  sim_k.cx = real_k.cx;
  sim_k.cy = real_k.cy;
  sim_k.validate();
  return sim_k;
}

// The corner scene's depth as the simulated camera sees it, before noise.
sensors::DepthImage render_corner_scene(const sensors::CameraIntrinsics& sim_k, const std::string& gl) {
  Scene scene;
  sensors::DepthRenderer renderer(scene.model, sim_k, sensors::parse_gl_backend(gl));
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  T_world_camera.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  T_world_camera.translation() = Eigen::Vector3d(0.0, 0.0, 1.0);
  return renderer.render(scene.model, scene.data, T_world_camera);
}

// Two noisy frames of the clean depth before (the default noise model) and after (the switches the real D435 calls
// for).
struct SimulatedFrames {
  sensors::DepthImage before[2];
  sensors::DepthImage after[2];
};

SimulatedFrames simulate_frames(const sensors::DepthImage& clean, const sensors::CameraIntrinsics& sim_k,
                                std::uint64_t seed) {
  sensors::DepthNoiseConfig before_config;                 // the default model
  sensors::DepthNoiseConfig after_config = before_config;  // the switches the real D435 calls for
  after_config.stereo_occlusion = true;
  after_config.correlated_fraction = 0.95;  // docs/fidelity.md: measured on the realdata D435 bag
  after_config.correlated_cell_px = 12.0;
  auto noisy = [&](const sensors::DepthNoiseConfig& config, std::uint64_t frame_index) {
    sensors::DepthNoise noise(config, sim_k);
    sensors::DepthImage image = clean;
    noise.apply(image, seed, frame_index);
    return image;
  };
  return {{noisy(before_config, 0), noisy(before_config, 1)}, {noisy(after_config, 0), noisy(after_config, 1)}};
}

void write_noise_stats_json(const NoiseStatsCommandOptions& o, const std::vector<NoiseStats>& stats,
                            const recording::RecordingInfo& info, const sensors::CameraIntrinsics& sim_k,
                            const NoiseStatsOptions& options) {
  const sensors::CameraIntrinsics& real_k = info.intrinsics;
  nlohmann::json j = {{"real", to_json(stats[0], real_k.fx, options)},
                      {"simulated_before", to_json(stats[1], sim_k.fx, options)},
                      {"simulated_after", to_json(stats[2], sim_k.fx, options)},
                      {"recording", {{"path", o.real}, {"format", info.format}, {"frames", info.frame_count}}},
                      {"intrinsics",
                       {{"width", real_k.width},
                        {"height", real_k.height},
                        {"fx", real_k.fx},
                        {"fy", real_k.fy},
                        {"cx", real_k.cx},
                        {"cy", real_k.cy}}},
                      {"formula", {{"baseline_m", options.baseline_m}, {"subpixel", options.subpixel}}},
                      {"seed", o.seed}};
  write_file_atomically(o.out, j.dump(2) + "\n");
  std::printf("\nwrote %s\n", o.out.c_str());
}

void write_noise_stats_figures(const std::string& figures, const RealFrames& real, const SimulatedFrames& sim) {
  const std::filesystem::path dir(figures);
  const double far_m = 3.5;
  sensors::write_depth_png_colorized(real.depth[0], (dir / "real.png").string(), 0.3, far_m);
  sensors::write_depth_png_colorized(sim.before[0], (dir / "simulated_before.png").string(), 0.3, far_m);
  sensors::write_depth_png_colorized(sim.after[0], (dir / "simulated_after.png").string(), 0.3, far_m);
  for (int k = 0; k < 2; ++k) {  // the frames themselves, 16-bit millimetres
    const std::string n = std::to_string(k);
    sensors::write_depth_png_mm(real.depth[k], (dir / ("real_mm_" + n + ".png")).string());
    sensors::write_depth_png_mm(sim.before[k], (dir / ("simulated_before_mm_" + n + ".png")).string());
    sensors::write_depth_png_mm(sim.after[k], (dir / ("simulated_after_mm_" + n + ".png")).string());
  }
  std::printf(
      "wrote real.png, simulated_before.png, simulated_after.png (colorized) and *_mm_0.png, *_mm_1.png "
      "(16-bit mm) in %s\n",
      figures.c_str());
}

int noise_stats(const NoiseStatsCommandOptions& o) {
  if (!o.out.empty()) ensure_writable_directory(std::filesystem::absolute(o.out).parent_path());
  if (!o.figures.empty()) ensure_writable_directory(o.figures);
  const RealFrames real = read_real_frames(o.real);
  const recording::RecordingInfo& info = real.info;
  const sensors::CameraIntrinsics& real_k = info.intrinsics;
  const sensors::CameraIntrinsics sim_k = simulated_intrinsics(real_k);
  const SimulatedFrames sim = simulate_frames(render_corner_scene(sim_k, o.gl), sim_k, o.seed);

  NoiseStatsOptions options;  // Intel's formula with the default noise model's stereo geometry
  options.baseline_m = sensors::DepthNoiseConfig().baseline_m;
  options.subpixel = sensors::DepthNoiseConfig().subpixel;
  const std::vector<NoiseStats> stats = {compute_noise_stats(real.depth[0], real.depth[1], real_k, options),
                                         compute_noise_stats(sim.before[0], sim.before[1], sim_k, options),
                                         compute_noise_stats(sim.after[0], sim.after[1], sim_k, options)};
  std::printf("real: %s (%s, %zu frames, %dx%d, fx %.2f, cx %.2f, cy %.2f); simulated: the corner scene, seed %llu\n\n",
              o.real.c_str(), info.format.c_str(), info.frame_count, real_k.width, real_k.height, real_k.fx, real_k.cx,
              real_k.cy, static_cast<unsigned long long>(o.seed));
  std::printf("%s",
              noise_stats_table({"real", "simulated before", "simulated after"}, stats, real_k.fx, options).c_str());

  if (!o.out.empty()) write_noise_stats_json(o, stats, info, sim_k, options);
  if (!o.figures.empty()) write_noise_stats_figures(o.figures, real, sim);
  return kExitOk;
}

const CommandRegistration kNoiseStats("noise-stats", [](CLI::App& app) {
  auto o = std::make_shared<NoiseStatsCommandOptions>();
  auto* cmd = app.add_subcommand(
      "noise-stats", "A real depth recording (two frames of a static camera) against the simulated D435 noise model");
  cmd->add_option("--real", o->real, "Recording: a ROS 1 bag or a folder of 16-bit depth PNGs (two frames or more)")
      ->required();
  cmd->add_option("--out", o->out, "Write the figures as JSON to this file");
  cmd->add_option("--figures", o->figures,
                  "Write the depth images (real, simulated before / after) here: colorized and 16-bit mm PNGs");
  cmd->add_option("--gl", o->gl, "auto | egl | osmesa")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Noise seed of the simulated frames")->capture_default_str();
  return [o] { return noise_stats(*o); };
});

}  // namespace
}  // namespace stvl::tools

// stvl-bench render --world W --frames N --out DIR: depth frames from the robot's camera as 16-bit PNG (mm) and
// a colorized PNG, while the robot drives (straight along +x, or a scenario's path with --scenario).
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "common/atomic_file.hpp"
#include "config/scenario.hpp"
#include "sensors/depth_noise.hpp"
#include "sensors/depth_renderer.hpp"
#include "sim/simulator.hpp"
#include "tools/command.hpp"

namespace stvl::tools {
using namespace stvl::config;
namespace {

struct RenderOptions {
  std::string world;
  std::string scenario;
  std::string out_dir;
  int frames = 10;
  std::string preset = "d435_848x480";
  double rate_hz = 15.0;
  double speed_mps = 0.5;
  std::string noise = "off";
  std::string gl = "auto";
  std::uint64_t seed = 1;
};

int render(const RenderOptions& o) {
  if (o.world.empty() == o.scenario.empty()) throw std::invalid_argument("give exactly one of --world and --scenario");
  if (o.frames < 1 || o.frames > 100000) throw std::invalid_argument("--frames must be in 1..100000");
  if (o.noise != "on" && o.noise != "off")
    throw std::invalid_argument("--noise must be on or off, got '" + o.noise + "'");
  Scenario s;
  if (!o.scenario.empty()) {
    s = load_scenario(o.scenario);
  } else {
    s.pipeline.world_path = o.world;
    s.pipeline.path.waypoints_W = {{0.0, 0.0}, {100.0, 0.0}};
    s.pipeline.path.cruise_speed_mps = o.speed_mps;
    auto& camera = s.camera();
    if (o.preset == "d435_640x480") camera.intrinsics = sensors::CameraIntrinsics::d435_640x480();
    else if (o.preset != "d435_848x480") throw std::invalid_argument("--preset must be d435_848x480 or d435_640x480");
    camera.intrinsics.rate_hz = o.rate_hz;
    camera.intrinsics.validate();
    camera.noise.enabled = o.noise == "on";
    camera.gl_backend = sensors::parse_gl_backend(o.gl);
    s.pipeline.seed = o.seed;
  }
  ensure_writable_directory(o.out_dir);
  const auto simulator = pipeline::make_simulator(s.pipeline);
  sim::Simulator& sim = *simulator;
  const auto& intrinsics = s.camera().intrinsics;
  sensors::DepthRenderer renderer(sim.world().model(), intrinsics, s.camera().gl_backend);
  sensors::DepthNoise noise(s.camera().noise, intrinsics);
  sensors::DepthImage image;
  double render_s = 0.0;
  for (int k = 0; k < o.frames; ++k) {
    sim.run_until(k * (1.0 / intrinsics.rate_hz));  // the frame times of a run
    const auto start = std::chrono::steady_clock::now();
    image = renderer.render(sim.world().model(), sim.world().data(), sim.T_world_camera());
    render_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    noise.apply(image, s.pipeline.seed, static_cast<std::uint64_t>(k));
    char name[32];
    std::snprintf(name, sizeof name, "depth_%05d", k);
    const std::filesystem::path base = std::filesystem::path(o.out_dir) / name;
    sensors::write_depth_png_mm(image, base.string() + ".png");
    sensors::write_depth_png_colorized(image, base.string() + "_color.png", intrinsics.min_range_m, 6.0);
  }
  std::printf("rendered %d frames of %dx%d with %s at %.1f frames/s (render only); PNGs in %s\n", o.frames,
              intrinsics.width, intrinsics.height, renderer.backend_name(), o.frames / render_s, o.out_dir.c_str());
  return kExitOk;
}

const CommandRegistration kRender("render", [](CLI::App& app) {
  auto o = std::make_shared<RenderOptions>();
  auto* cmd = app.add_subcommand("render", "Render depth frames from the robot's camera to 16-bit and colorized PNG");
  cmd->add_option("--world", o->world, "MJCF world (the robot drives straight along +x)");
  cmd->add_option("--scenario", o->scenario, "Scenario YAML (its world, path, camera and noise)");
  cmd->add_option("--frames", o->frames, "Number of frames")->capture_default_str();
  cmd->add_option("--out", o->out_dir, "Output directory")->required();
  cmd->add_option("--preset", o->preset, "d435_848x480 | d435_640x480 (with --world)")->capture_default_str();
  cmd->add_option("--rate", o->rate_hz, "Frame rate in Hz (with --world)")->capture_default_str();
  cmd->add_option("--speed", o->speed_mps, "Robot speed in m/s (with --world)")->capture_default_str();
  cmd->add_option("--noise", o->noise, "on | off (with --world)")->capture_default_str();
  cmd->add_option("--gl", o->gl, "auto | egl | osmesa (with --world)")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Noise seed (with --world)")->capture_default_str();
  return [o] { return render(*o); };
});

}  // namespace
}  // namespace stvl::tools

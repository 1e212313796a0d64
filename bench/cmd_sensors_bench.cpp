// `stvl-bench sensors-bench`: depth rendering frames per second per GL backend and image size
// (bench/sensors_bench.cpp).
#include <memory>

#include "bench/sensors_bench.hpp"
#include "tools/command.hpp"

namespace stvl::bench {
namespace {

const tools::CommandRegistration kSensorsBench("sensors-bench", [](CLI::App& app) {
  auto* cmd = app.add_subcommand("sensors-bench",
                                 "Depth frames per second per GL backend, render only and with noise and cloud");
  auto o = std::make_shared<SensorsBenchOptions>();
  cmd->add_option("--world", o->world_path, "MJCF world to render (default: a built-in corridor)");
  cmd->add_option("--gl", o->backends, "GL backends, each in its own process: osmesa, egl, auto")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--frames", o->frames, "Timed frames per row")->capture_default_str();
  return [o] {
    run_sensors_bench(*o);
    return tools::kExitOk;
  };
});

}  // namespace
}  // namespace stvl::bench

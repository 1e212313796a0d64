// `stvl-bench sim-bench`: physics steps per second with the robot driving (bench/sim_bench.cpp).
#include <memory>
#include <string>

#include "bench/sim_bench.hpp"
#include "tools/command.hpp"

namespace stvl::bench {
namespace {

const tools::CommandRegistration kSimBench("sim-bench", [](CLI::App& app) {
  auto* cmd =
      app.add_subcommand("sim-bench", "Physics throughput: steps per second with the robot driving the corridor");
  auto o = std::make_shared<SimBenchOptions>();
  o->world_path = std::string(STVL_SOURCE_DIR) + "/worlds/office_corridor.xml";
  cmd->add_option("--world", o->world_path, "MJCF world with the robot")->capture_default_str();
  cmd->add_option("--duration", o->duration_s, "Simulated seconds")->capture_default_str();
  return [o] {
    print_sim_bench(*o, run_sim_bench(*o));
    return tools::kExitOk;
  };
});

}  // namespace
}  // namespace stvl::bench

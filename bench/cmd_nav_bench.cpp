// `stvl-bench nav-bench`: NavFn and nav2's inflation on a 20 x 12 m office at 0.05 m (bench/nav_bench.cpp).
#include <iostream>
#include <memory>

#include "bench/nav_bench.hpp"
#include "tools/command.hpp"

namespace stvl::bench {
namespace {

const tools::CommandRegistration kNavBench("nav-bench", [](CLI::App& app) {
  auto* cmd =
      app.add_subcommand("nav-bench", "NavFn (Dijkstra, A*) and nav2's inflation on an office's global costmap");
  auto options = std::make_shared<NavBenchOptions>();
  cmd->add_option("--width-m", options->width_m, "the office's width in m");
  cmd->add_option("--height-m", options->height_m, "the office's height in m");
  cmd->add_option("--resolution-m", options->resolution_m, "cell size in m");
  cmd->add_option("--repetitions", options->repetitions, "timed runs of each");
  return [options] {
    print_nav_bench(run_nav_bench(*options), std::cout);
    return tools::kExitOk;
  };
});

}  // namespace
}  // namespace stvl::bench

// `stvl-bench map-bench`: the voxel map's per-frame cost against a full walk and OctoMap (bench/map_bench.cpp).
#include <iostream>
#include <memory>

#include "bench/map_bench.hpp"
#include "tools/command.hpp"

namespace stvl::bench {
namespace {

struct MapBenchCli {
  MapBenchOptions options;
  bool no_octomap = false;
};

const tools::CommandRegistration kMapBench("map-bench", [](CLI::App& app) {
  auto* cmd = app.add_subcommand("map-bench", "per-frame mark/clear cost of the voxel map vs map size, with peers");
  auto cli = std::make_shared<MapBenchCli>();
  cmd->add_option("--voxel-size", cli->options.voxel_size_m, "voxel size in m");
  cmd->add_option("--frames", cli->options.frames, "synthetic frames per map size");
  cmd->add_option("--sizes", cli->options.sizes, "pre-filled voxel counts, comma separated")->delimiter(',');
  cmd->add_option("--seed", cli->options.seed, "seed of the synthetic frames");
  cmd->add_flag("--no-octomap", cli->no_octomap, "skip the OctoMap peer");
  cmd->add_option("--threads", cli->options.threads, "threads for the map's ray walks (0: all cores)");
  return [cli] {
    cli->options.octomap = !cli->no_octomap;
    print_map_bench(run_map_bench(cli->options), std::cout);
    return tools::kExitOk;
  };
});

}  // namespace
}  // namespace stvl::bench

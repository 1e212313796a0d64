// `stvl-bench layer-bench`: STVL's layer against nav2's VoxelLayer and ObstacleLayer on the same frames
// (bench/layer_bench.cpp).
#include <iostream>
#include <memory>

#include "bench/layer_bench.hpp"
#include "tools/command.hpp"

namespace stvl::bench {
namespace {

const tools::CommandRegistration kLayerBench("layer-bench", [](CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "layer-bench", "per-update cost of STVL's layer, nav2's VoxelLayer and ObstacleLayer on the same frames");
  auto options = std::make_shared<LayerBenchOptions>();
  cmd->add_option("--voxel-size", options->voxel_size_m, "voxel size (nav2: resolution and z_resolution) in m");
  cmd->add_option("--frames", options->frames, "instants per configuration");
  cmd->add_option("--sizes", options->sizes, "map sizes in voxels, comma separated")->delimiter(',');
  cmd->add_option("--cameras", options->cameras, "cameras at once, comma separated (1..3)")->delimiter(',');
  cmd->add_option("--seed", options->seed, "seed of the synthetic frames");
  return [options] {
    print_layer_bench(run_layer_bench(*options), std::cout);
    return tools::kExitOk;
  };
});

}  // namespace
}  // namespace stvl::bench

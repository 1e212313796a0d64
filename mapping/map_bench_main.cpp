// Standalone `map-bench` so the mapping module can be measured without the other modules.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <iostream>

#include "mapping/benchmark.hpp"

int main(int argc, char** argv) {
  CLI::App app{"map-bench: per-frame mark/clear cost of the STVL voxel map vs map size"};
  stvl::mapping::MapBenchOptions options;
  bool no_octomap = false;
  app.add_option("--voxel-size", options.voxel_size_m, "voxel size in m");
  app.add_option("--frames", options.frames, "synthetic frames per map size");
  app.add_option("--sizes", options.sizes, "pre-filled voxel counts")->delimiter(',');
  app.add_option("--seed", options.seed, "seed of the synthetic frames");
  app.add_flag("--no-octomap", no_octomap, "skip the OctoMap peer");
  app.add_option("--threads", options.threads, "threads for the ray walks (0: all cores)");
  CLI11_PARSE(app, argc, argv);
  options.octomap = !no_octomap;
  try {
    stvl::mapping::print_map_bench(stvl::mapping::run_map_bench(options), std::cout);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "map-bench: error: %s\n", e.what());
    return 2;
  }
  return 0;
}

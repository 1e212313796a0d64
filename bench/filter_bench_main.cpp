// filter-bench-standalone [--cloud FILE]... [--voxel M]... [--warmup N] [--reps N] [--threads N] [--max-neighbours N]
//                         [--batch N] [--save FILE] [--no-cuda] [--no-cpu] [--filters voxel,csnb]
// Without --cloud it benchmarks the synthetic 848x480 corridor cloud (bench/synthetic_corridor.hpp). For a machine
// without our Debian packages: built by `cmake -S filter` (Eigen, optional CUDA) as well as by the whole project.
#include <algorithm>
#include <exception>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/cloud_io.hpp"
#include "bench/filter_bench.hpp"
#include "bench/synthetic_corridor.hpp"

int main(int argc, char** argv) {
  using namespace stvl::bench;
  namespace filter = stvl::filter;
  try {
    std::vector<BenchmarkCloud> clouds;
    FilterBenchConfig config;
    std::vector<double> voxels;
    std::string save_path;
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument("missing value after " + arg);
        return argv[++i];
      };
      if (arg == "--cloud") {
        const std::string path = value();
        clouds.push_back({path, load_cloud(path)});
      } else if (arg == "--voxel") {
        voxels.push_back(std::stod(value()));
      } else if (arg == "--warmup") {
        config.warmup = std::stoi(value());
      } else if (arg == "--reps") {
        config.repetitions = std::stoi(value());
      } else if (arg == "--threads") {
        config.cpu_threads = std::stoi(value());
      } else if (arg == "--max-neighbours") {
        config.csnb.max_neighbours = std::stoi(value());
      } else if (arg == "--batch") {
        config.csnb.batch_size = std::stoi(value());
      } else if (arg == "--save") {
        save_path = value();
      } else if (arg == "--no-cuda") {
        config.cuda = false;
      } else if (arg == "--no-cpu") {
        config.cpu = false;
      } else if (arg == "--filters") {
        config.filters.clear();
        std::string list = value();
        for (std::size_t start = 0; start <= list.size();) {
          const std::size_t comma = std::min(list.find(',', start), list.size());
          config.filters.push_back(filter::parse_filter_type(list.substr(start, comma - start)));
          start = comma + 1;
        }
      } else {
        throw std::invalid_argument("unknown argument '" + arg + "'");
      }
    }
    if (!voxels.empty()) config.voxel_sizes_m = voxels;
    if (clouds.empty()) clouds.push_back({"corridor-synthetic", make_corridor_cloud(1)});
    if (!save_path.empty()) save_cloud(save_path, clouds.front().points);
    std::string reason;
    if (config.cuda && !filter::cuda_available(&reason)) std::cerr << "no CUDA rows: " << reason << "\n";
    print_filter_bench_table(std::cout, run_filter_bench(clouds, config), "voxel/cpu");
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "filter-bench-standalone: " << e.what() << "\n";
    return 2;
  }
}

// stvl-bench filter-bench: every filter on D435-sized clouds rendered from the corridor, on the CPU and (where
// present) CUDA in every memory mode, mean and standard deviation in ms, optionally against PCL's VoxelGrid.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/cloud_io.hpp"
#include "bench/filter_bench.hpp"
#include "bench/pcl_peer.hpp"
#include "common/atomic_file.hpp"
#include "config/scenario.hpp"
#include "pipeline/pipeline.hpp"
#include "sensors/depth_noise.hpp"
#include "sensors/depth_renderer.hpp"
#include "sim/simulator.hpp"
#include "tools/command.hpp"

namespace stvl::bench {
namespace {

using config::Scenario;

struct FilterBenchCli {
  std::string scenario;
  int clouds = 3;
  std::vector<double> voxel_sizes_m{0.02, 0.05, 0.10};
  std::vector<std::string> filters{"voxel", "csnb"};
  int warmup = 3;
  int repetitions = 20;
  int threads = 0;
  bool no_cuda = false;
  std::string peer;
  std::string save_clouds;
};

// Clouds in the world frame from the scenario's drive, evenly spaced over its first 20 s.
std::vector<BenchmarkCloud> render_clouds(const Scenario& s, int count) {
  const auto simulator = pipeline::make_simulator(s.pipeline);
  sim::Simulator& sim = *simulator;
  sensors::DepthRenderer renderer(sim.world().model(), s.camera().intrinsics, s.camera().gl_backend);
  sensors::DepthNoise noise(s.camera().noise, s.camera().intrinsics);
  std::vector<BenchmarkCloud> clouds;
  for (int k = 0; k < count; ++k) {
    const double t = 2.0 + 18.0 * k / std::max(1, count - 1);
    sim.run_until(t);
    sensors::DepthImage image = renderer.render(sim.world().model(), sim.world().data(), sim.T_world_camera());
    noise.apply(image, s.pipeline.seed, static_cast<std::uint64_t>(k));
    const Eigen::Matrix3Xf points_C = sensors::depth_to_cloud(image, s.camera().intrinsics);
    const Eigen::Isometry3f T = sim.T_world_camera().cast<float>();
    char name[32];
    std::snprintf(name, sizeof name, "corridor_t%04.1f", t);
    clouds.push_back({name, (T.linear() * points_C).colwise() + T.translation()});
  }
  return clouds;
}

int filter_bench(const FilterBenchCli& o) {
  if (o.clouds < 1 || o.clouds > 100) throw std::invalid_argument("--clouds must be in 1..100");
  if (o.repetitions < 1 || o.warmup < 0) throw std::invalid_argument("--reps must be >= 1 and --warmup >= 0");
  if (!o.peer.empty() && o.peer != "pcl") throw std::invalid_argument("--peer must be pcl, got '" + o.peer + "'");
  if (o.peer == "pcl" && !pcl_peer_available()) run_pcl_peer({}, {}, 0, 0);  // throws the explanation
  FilterBenchConfig config;
  config.voxel_sizes_m = o.voxel_sizes_m;
  config.filters.clear();
  for (const auto& f : o.filters) config.filters.push_back(filter::parse_filter_type(f));
  config.cuda = !o.no_cuda;
  config.cpu_threads = o.threads;
  config.warmup = o.warmup;
  config.repetitions = o.repetitions;
  Scenario scenario = config::load_scenario(o.scenario.empty() ? config::default_scenario_path() : o.scenario);
  const auto clouds = render_clouds(scenario, o.clouds);
  if (!o.save_clouds.empty()) {
    ensure_writable_directory(o.save_clouds);
    for (const auto& c : clouds)
      save_cloud((std::filesystem::path(o.save_clouds) / (c.name + ".stvlcld")).string(), c.points);
  }
  std::printf(
      "filter-bench: %d clouds of %dx%d rendered from %s (noise %s), %d threads (0: all cores), %d repetitions after "
      "%d warm-up\n",
      o.clouds, scenario.camera().intrinsics.width, scenario.camera().intrinsics.height,
      scenario.pipeline.world_path.c_str(), scenario.camera().noise.enabled ? "on" : "off", o.threads, o.repetitions,
      o.warmup);
  std::vector<FilterBenchRow> rows;
  std::string baseline = "voxel/cpu";
  if (o.peer == "pcl") {
    // The bench's filters and PCL's back to back for each cloud and voxel size, so that the ratio compares like with
    // like on a machine whose speed drifts.
    baseline = "pcl2/cpu";
    for (const auto& cloud : clouds) {
      for (double voxel_m : o.voxel_sizes_m) {
        FilterBenchConfig one = config;
        one.voxel_sizes_m = {voxel_m};
        for (auto part : {run_filter_bench({cloud}, one), run_pcl_peer({cloud}, {voxel_m}, o.warmup, o.repetitions)})
          rows.insert(rows.end(), part.begin(), part.end());
      }
    }
  } else {
    rows = run_filter_bench(clouds, config);
  }
  print_filter_bench_table(std::cout, rows, baseline);
  return tools::kExitOk;
}

const tools::CommandRegistration kFilterBench("filter-bench", [](CLI::App& app) {
  auto o = std::make_shared<FilterBenchCli>();
  auto* cmd = app.add_subcommand("filter-bench", "Benchmark the filters on clouds rendered from the corridor");
  cmd->add_option("--scenario", o->scenario,
                  "Scenario whose world, path and camera make the clouds (default: the default scenario)");
  cmd->add_option("--clouds", o->clouds, "Number of rendered clouds")->capture_default_str();
  cmd->add_option("--voxel", o->voxel_sizes_m, "Voxel sizes in m")->delimiter(',')->capture_default_str();
  cmd->add_option("--filters", o->filters, "Filters: voxel, csnb")->delimiter(',')->capture_default_str();
  cmd->add_option("--warmup", o->warmup, "Warm-up calls per row")->capture_default_str();
  cmd->add_option("--reps", o->repetitions, "Timed calls per row")->capture_default_str();
  cmd->add_option("--threads", o->threads, "CPU threads (0: all cores)")->capture_default_str();
  cmd->add_flag("--no-cuda", o->no_cuda, "Skip the CUDA rows");
  cmd->add_option("--peer", o->peer, "pcl: also run PCL's VoxelGrid on the same clouds (needs libpcl-dev)");
  cmd->add_option("--save-clouds", o->save_clouds, "Also save the clouds as .stvlcld files in this directory");
  return [o] { return filter_bench(*o); };
});

}  // namespace
}  // namespace stvl::bench

#include "bench/sim_bench.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "common/stopwatch.hpp"
#include "sim/simulator.hpp"

namespace stvl::bench {

void SimBenchOptions::validate() const {
  if (world_path.empty()) throw std::invalid_argument("sim-bench: no world given");
  if (!(duration_s > 0.0 && duration_s <= 3600.0))
    throw std::invalid_argument("duration_s = " + std::to_string(duration_s) + " must lie in (0, 3600]");
}

SimBenchResult run_sim_bench(const SimBenchOptions& options) {
  options.validate();
  sim::Simulator sim(sim::World::from_file(options.world_path));
  const bool l_turn = options.world_path.find("l_corridor") != std::string::npos;
  sim.set_path(l_turn ? sim::Path{{{0, 0}, {8, 0}, {8, 7}}, 0.8} : sim::Path{{{0, 0}, {20, 0}}, 0.8});
  SimBenchResult result;
  const Stopwatch watch;
  while (sim.time_s() < options.duration_s) {
    sim.step();
    ++result.steps;
  }
  result.wall_s = watch.elapsed_s();
  result.simulated_s = sim.time_s();
  const Eigen::Vector3d p = sim.T_world_base().translation();
  result.final_x_m = p.x();
  result.final_y_m = p.y();
  return result;
}

void print_sim_bench(const SimBenchOptions& options, const SimBenchResult& r) {
  std::printf(
      "world %s: %ld steps (%.1f s simulated) in %.3f s wall: %.0f steps/s, %.1fx real time; robot at x=%.2f y=%.2f\n",
      options.world_path.c_str(), r.steps, r.simulated_s, r.wall_s, r.steps / r.wall_s, r.simulated_s / r.wall_s,
      r.final_x_m, r.final_y_m);
}

}  // namespace stvl::bench

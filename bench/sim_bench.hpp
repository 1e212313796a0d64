#pragma once
// `stvl-bench sim-bench`: physics throughput, steps per second with the robot driving down a world's corridor.
#include <string>

namespace stvl::bench {

struct SimBenchOptions {
  std::string world_path;    // MJCF world with the robot; a path containing "l_corridor" drives the L-turn
  double duration_s = 20.0;  // simulated time
  void validate() const;     // throws std::invalid_argument
};

struct SimBenchResult {
  long steps = 0;
  double simulated_s = 0.0;
  double wall_s = 0.0;
  double final_x_m = 0.0, final_y_m = 0.0;  // where the robot ended up
};

// Throws what loading the world throws (std::invalid_argument for a bad MJCF file).
SimBenchResult run_sim_bench(const SimBenchOptions& options);
// One line: steps, simulated and wall time, steps/s, real-time factor, the robot's final position.
void print_sim_bench(const SimBenchOptions& options, const SimBenchResult& result);

}  // namespace stvl::bench

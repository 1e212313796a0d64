#pragma once
// `stvl-bench nav-bench`: nav2's NavFn (Dijkstra and A*) and inflation on a synthetic office's global costmap, the
// size of a generated office (20 x 12 m at 0.05 m: 400 x 240 cells), on one core; inflation beside its
// brute-force reference, A* beside Dijkstra, in the same run.
#include <ostream>

namespace stvl::bench {

struct NavBenchOptions {
  double width_m = 20.0, height_m = 12.0, resolution_m = 0.05;
  int repetitions = 30;
};

struct NavBenchResult {
  int width = 0, height = 0;
  double inflate_ms = 0, inflate_reference_ms = 0;
  double dijkstra_ms = 0, astar_ms = 0, dijkstra_length_m = 0, astar_length_m = 0;
};

NavBenchResult run_nav_bench(const NavBenchOptions& options);
void print_nav_bench(const NavBenchResult& r, std::ostream& out);

}  // namespace stvl::bench

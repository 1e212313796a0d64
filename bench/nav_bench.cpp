#include "bench/nav_bench.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "bench/timing.hpp"
#include "navigation/inflation.hpp"
#include "navigation/navfn.hpp"

namespace stvl::bench {
namespace {

// Outer walls, a corridor along y = height / 2 with rooms on both sides (walls every 4 m, a 1 m door in each),
// desks as lethal blocks: a global costmap like a generated office's static map with some furniture.
mapping::Costmap2D office(const NavBenchOptions& o) {
  mapping::Costmap2D m;
  m.resolution_m = o.resolution_m;
  m.width = static_cast<int>(std::lround(o.width_m / o.resolution_m));
  m.height = static_cast<int>(std::lround(o.height_m / o.resolution_m));
  m.cells.assign(static_cast<std::size_t>(m.width) * m.height, mapping::kCostFree);
  const auto wall = [&](double x0, double y0, double x1, double y1) {
    for (int y = std::max(0, static_cast<int>(y0 / o.resolution_m));
         y <= std::min(m.height - 1, static_cast<int>(y1 / o.resolution_m)); ++y)
      for (int x = std::max(0, static_cast<int>(x0 / o.resolution_m));
           x <= std::min(m.width - 1, static_cast<int>(x1 / o.resolution_m)); ++x)
        m.cells[static_cast<std::size_t>(y) * m.width + x] = mapping::kCostLethal;
  };
  const double w = o.width_m, h = o.height_m, c = h / 2;
  wall(0, 0, w, 0.05), wall(0, h - 0.05, w, h), wall(0, 0, 0.05, h), wall(w - 0.05, 0, w, h);
  for (double x = 0; x < w; x += 4.0) {  // corridor walls with doors into the rooms
    wall(x, c - 1.05, x + 1.5, c - 1.0), wall(x + 2.5, c - 1.05, x + 4.0, c - 1.0);
    wall(x, c + 1.0, x + 1.5, c + 1.05), wall(x + 2.5, c + 1.0, x + 4.0, c + 1.05);
    wall(x, 0, x + 0.05, c - 1.0), wall(x, c + 1.0, x + 0.05, h);                // room walls
    wall(x + 0.8, 0.8, x + 2.2, 1.5), wall(x + 1.6, h - 1.5, x + 3.0, h - 0.8);  // desks
  }
  return m;
}

}  // namespace

NavBenchResult run_nav_bench(const NavBenchOptions& o) {
  if (!(o.resolution_m > 0) || !(o.width_m >= 8) || !(o.height_m >= 8) || o.repetitions < 1)
    throw std::invalid_argument("nav-bench: sizes of at least 8 m, a resolution > 0 and repetitions >= 1");
  const mapping::Costmap2D grid = office(o);
  NavBenchResult r;
  r.width = grid.width, r.height = grid.height;
  const navigation::InflationParams inflation{0.70, 3.0, false, false};  // nav2_bringup's
  const double inscribed = 0.22 * std::cos(M_PI / 16) + 0.01;            // nav2_bringup's robot_radius 0.22, padded
  mapping::Costmap2D inflated = grid;
  r.inflate_ms = time_ms(
                     [&] {
                       inflated = grid;
                       navigation::inflate(inflated, inscribed, inflation);
                     },
                     1, o.repetitions)
                     .first;
  mapping::Costmap2D reference = grid;
  r.inflate_reference_ms = time_ms(
                               [&] {
                                 reference = grid;
                                 navigation::inflate_reference(reference, inscribed, inflation);
                               },
                               0, std::max(1, o.repetitions / 10))
                               .first;
  // From a room at one end to a room at the other, through two doors and the corridor.
  const Eigen::Vector2d start(1.0, 2.5), goal(o.width_m - 2.0, o.height_m - 2.5);
  navigation::NavfnParams planner;
  navigation::PlanResult plan;
  r.dijkstra_ms =
      time_ms([&] { plan = navigation::navfn_plan(inflated, start, goal, planner); }, 1, o.repetitions).first;
  if (!plan.found) throw std::runtime_error("nav-bench: NavFn found no plan (" + plan.failure + ")");
  r.dijkstra_length_m = navigation::path_length_m(plan.path_W);
  planner.use_astar = true;
  r.astar_ms = time_ms([&] { plan = navigation::navfn_plan(inflated, start, goal, planner); }, 1, o.repetitions).first;
  r.astar_length_m = navigation::path_length_m(plan.path_W);
  return r;
}

void print_nav_bench(const NavBenchResult& r, std::ostream& out) {
  out << "nav-bench: " << r.width << " x " << r.height << " cells, one core\n";
  out << "  inflate (nav2's propagation)   " << r.inflate_ms << " ms   (brute-force reference "
      << r.inflate_reference_ms << " ms, ratio " << r.inflate_reference_ms / r.inflate_ms << ")\n";
  out << "  NavFn Dijkstra                 " << r.dijkstra_ms << " ms   (path " << r.dijkstra_length_m << " m)\n";
  out << "  NavFn A*                       " << r.astar_ms << " ms   (path " << r.astar_length_m << " m, "
      << r.astar_ms / r.dijkstra_ms << " of Dijkstra's time)\n";
}

}  // namespace stvl::bench

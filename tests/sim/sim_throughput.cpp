// Physics throughput with the robot driving: sim_throughput [world.xml] [simulated seconds].
#include <chrono>
#include <cstdio>
#include <exception>
#include <string>

#include "sim/simulator.hpp"

int main(int argc, char** argv) {
  try {
    const std::string path = argc > 1 ? argv[1] : std::string(STVL_SOURCE_DIR) + "/worlds/office_corridor.xml";
    const double duration_s = argc > 2 ? std::stod(argv[2]) : 20.0;
    stvl::sim::Simulator sim(stvl::sim::World::from_file(path));
    const bool l_turn = path.find("l_corridor") != std::string::npos;
    sim.set_path(l_turn ? stvl::sim::Path{{{0, 0}, {8, 0}, {8, 7}}, 0.8} : stvl::sim::Path{{{0, 0}, {20, 0}}, 0.8});
    const auto start = std::chrono::steady_clock::now();
    long steps = 0;
    while (sim.time_s() < duration_s) {
      sim.step();
      ++steps;
    }
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const Eigen::Vector3d p = sim.T_world_base().translation();
    std::printf("world %s: %ld steps (%.1f s simulated) in %.3f s wall: %.0f steps/s, %.1fx real time; robot at x=%.2f y=%.2f\n",
                path.c_str(), steps, sim.time_s(), wall_s, steps / wall_s, sim.time_s() / wall_s, p.x(), p.y());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sim_throughput: %s\n", e.what());
    return 2;
  }
}

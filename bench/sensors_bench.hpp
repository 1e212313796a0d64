#pragma once
// `stvl-bench sensors-bench`: depth frames per second, render only and render + noise + cloud, at 640x480 and
// 848x480, for each GL backend. Each backend runs in its own child process so that one does not decide MuJoCo's
// GL binding for the other.
#include <string>
#include <vector>

namespace stvl::bench {

struct SensorsBenchOptions {
  std::string world_path;  // empty: a built-in 3 m wide corridor with boxes, cylinders and spheres
  std::vector<std::string> backends{"osmesa", "egl"};  // "osmesa", "egl" or "auto"
  int frames = 300;       // timed frames per row (1..1000: 1 cm apart along +x), after 10 warm-up frames
  void validate() const;  // throws std::invalid_argument
};

// Prints a header and one row per backend and image size on stdout (a backend that cannot start prints
// "unavailable" and its reason). Throws std::invalid_argument for bad options.
void run_sensors_bench(const SensorsBenchOptions& options);

}  // namespace stvl::bench

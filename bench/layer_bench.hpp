#pragma once
// `stvl-bench layer-bench`: the three layers' update cost on the same frames in one run: STVL's layer (with the
// bench's bounded clearing walk, and with STVL's own full walk of every voxel), nav2's VoxelLayer and nav2's
// ObstacleLayer (layer::make_layer), fed the synthetic corridor's voxel-filtered D435-like frames
// (bench/synthetic_corridor.hpp) from 1 to 3 cameras at once, as the map grows: STVL's map pre-filled with voxels
// behind the camera, nav2's grids as windows of that many voxels (columns x z_voxels; a window narrower than the
// camera's 5 m clips its rays). Per update: the wall-clock milliseconds of Layer::update (buffering, clearing,
// marking; nav2's costmap cycle, combination into the master included), mean and p95; and the bytes of the layer's map
// at the end (Layer::map_bytes: STVL's OpenVDB tree, nav2's 32-bit columns and 1-byte cells).
#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

namespace stvl::bench {

struct LayerBenchOptions {
  double voxel_size_m = 0.05;  // STVL's voxel size and nav2's resolution (and z_resolution)
  int frames = 60;             // instants per configuration (30 per s)
  std::vector<std::size_t> sizes = {10'000, 100'000, 1'000'000};  // map sizes (voxels)
  std::vector<int> cameras = {1, 2, 3};
  std::uint64_t seed = 1;
  void validate() const;  // throws std::invalid_argument
};

struct LayerBenchRow {
  std::string layer;  // stvl | stvl_full_walk | nav2_voxel | nav2_obstacle
  std::size_t size = 0;
  int cameras = 1;
  double mean_ms = 0.0, p95_ms = 0.0;  // per update (one per instant)
  double map_mib = 0.0;                // Layer::map_bytes at the end
  std::size_t final_voxels = 0, final_lethal_cells = 0;
};

struct LayerBenchResult {
  LayerBenchOptions options;
  double points_per_frame = 0.0;
  std::vector<LayerBenchRow> rows;  // sizes x cameras x layers, in that order
};

LayerBenchResult run_layer_bench(const LayerBenchOptions& options);
void print_layer_bench(const LayerBenchResult& result, std::ostream& out);

}  // namespace stvl::bench

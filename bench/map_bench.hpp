#pragma once
// `stvl-bench map-bench`: per-frame mark and clear cost of the voxel map as the map grows, against the
// STVL-style full walk and OctoMap's insertPointCloud (when liboctomap was found) in the same run, on the
// synthetic corridor's frames (bench/synthetic_corridor.hpp).
#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <vector>

namespace stvl::bench {

struct MapBenchOptions {
  double voxel_size_m = 0.05;
  int frames = 60;
  std::vector<std::size_t> sizes = {10'000, 100'000, 1'000'000};  // pre-filled voxels outside the view
  std::uint64_t seed = 1;
  bool octomap = true;    // run the OctoMap peer when available
  int threads = 0;        // threads for the map's parallel ray walks (0: all cores); OctoMap's insert is serial
  void validate() const;  // throws std::invalid_argument
};

struct MapBenchRow {
  std::size_t prefilled_voxels = 0;
  double mark_ms = 0.0;   // medians per frame
  double clear_ms = 0.0;  // bounded walk (the bench's)
  double full_walk_clear_ms = 0.0;
  double raycast_clear_ms = 0.0;
  double raycast_mark_ms = 0.0;
  double octomap_insert_ms = 0.0;  // OctoMap peer, fresh OcTree, same clouds/origins/voxel size/max range
  std::size_t final_voxels = 0;
  bool full_walk_matches = false;  // bounded and full-walk maps hold the same voxels and times at the end
};

struct MapBenchResult {
  MapBenchOptions options;
  double points_per_frame = 0.0;
  std::vector<MapBenchRow> rows;
  bool have_octomap = false;
};

MapBenchResult run_map_bench(const MapBenchOptions& options);
void print_map_bench(const MapBenchResult& result, std::ostream& out);

}  // namespace stvl::bench

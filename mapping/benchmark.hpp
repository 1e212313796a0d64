#pragma once
// `map-bench`: per-frame mark and clear cost of the voxel map as the map grows, against the STVL-style full
// walk and OctoMap's insertPointCloud (when liboctomap was found) in the same run.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <vector>

namespace stvl::mapping {

struct MapBenchOptions {
  double voxel_size_m = 0.05;
  int frames = 60;
  std::vector<std::size_t> sizes = {10'000, 100'000, 1'000'000};  // pre-filled voxels outside the view
  std::uint64_t seed = 1;
  bool octomap = true;  // run the OctoMap peer when available
  int threads = 0;      // threads for the map's parallel ray walks (0: all cores); OctoMap's insert is serial
  void validate() const;  // throws std::invalid_argument
};

// One synthetic D435-like frame (424x240, 87 x 58 deg, 0.2..5 m, depth noise 1 mm * z^2) in a 2 m wide
// corridor with boxes, voxel-filtered (centroid per voxel) at voxel_size. Deterministic in (seed, frame).
struct SyntheticFrame {
  Eigen::Matrix3Xf points_W;
  Eigen::Isometry3d T_world_camera;  // optical frame
  double time_s = 0.0;
};
SyntheticFrame synthetic_corridor_frame(std::uint64_t seed, int frame, double voxel_size_m);

struct MapBenchRow {
  std::size_t prefilled_voxels = 0;
  double mark_ms = 0.0;          // medians per frame
  double clear_ms = 0.0;         // bounded walk (ours)
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

}  // namespace stvl::mapping

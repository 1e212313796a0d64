#include "bench/map_bench.hpp"

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <memory>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <string>

#include "bench/octomap_peer.hpp"
#include "bench/synthetic_corridor.hpp"
#include "bench/timing.hpp"
#include "common/statistics.hpp"
#include "mapping/voxel_map.hpp"

namespace stvl::bench {

using mapping::ClearingMode;
using mapping::ClearingObservation;
using mapping::ClearingWalk;
using mapping::ObservationSource;
using mapping::StvlConfig;
using mapping::Voxel;
using mapping::VoxelMap;

namespace {

ObservationSource bench_source() {
  ObservationSource source;
  source.marking = true;
  source.clearing = true;
  source.obstacle_range_m = kFrameMaxRangeM;
  source.min_obstacle_height_m = 0.05;
  source.max_obstacle_height_m = 2.0;
  source.horizontal_fov_rad = kFrameHorizontalFovRad;
  source.vertical_fov_rad = kFrameVerticalFovRad;
  source.min_z_m = kFrameMinRangeM;
  source.max_z_m = kFrameMaxRangeM;
  source.decay_acceleration_per_s3 = 1.0;
  return source;
}

// Voxels behind the camera's path (100 voxels from y = -20 m on, 100 across, then up), all marked at t = 0.
std::vector<Voxel> prefill(std::size_t count, double voxel_size_m) {
  std::vector<Voxel> voxels;
  voxels.reserve(count);
  const int y0 = static_cast<int>(std::floor(-20.0 / voxel_size_m));
  for (std::size_t i = 0; i < count; ++i) {
    const int along = static_cast<int>(i % 100), across = static_cast<int>((i / 100) % 100),
              up = static_cast<int>(i / 10000);
    voxels.push_back({{across - 50, y0 + along, up}, 0.0});
  }
  return voxels;
}

}  // namespace

void MapBenchOptions::validate() const {
  StvlConfig config;
  config.voxel_size_m = voxel_size_m;
  config.validate();
  if (frames < 1 || frames > 100000)
    throw std::invalid_argument("frames = " + std::to_string(frames) + " must lie in [1, 100000]");
  if (sizes.empty()) throw std::invalid_argument("sizes is empty");
  if (threads < 0 || threads > 1024)
    throw std::invalid_argument("threads = " + std::to_string(threads) + " must lie in [0, 1024]");
  for (std::size_t s : sizes)
    if (s > 10'000'000) throw std::invalid_argument("size = " + std::to_string(s) + " exceeds 10^7 voxels");
}

MapBenchResult run_map_bench(const MapBenchOptions& options) {
  options.validate();
  std::unique_ptr<tbb::global_control> limit;
  if (options.threads > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, options.threads);
  MapBenchResult result;
  result.options = options;
  result.have_octomap = options.octomap && OctomapPeer::available();
  std::vector<SyntheticFrame> frames;
  double total_points = 0.0;
  for (int f = 0; f < options.frames; ++f) {
    frames.push_back(synthetic_corridor_frame(options.seed, f, options.voxel_size_m));
    total_points += static_cast<double>(frames.back().points_W.cols());
  }
  result.points_per_frame = total_points / options.frames;
  const ObservationSource source = bench_source();

  for (std::size_t size : options.sizes) {
    MapBenchRow row;
    row.prefilled_voxels = size;
    const std::vector<Voxel> fill = prefill(size, options.voxel_size_m);
    StvlConfig config;
    config.voxel_size_m = options.voxel_size_m;
    VoxelMap ours(config);
    config.clearing_walk = ClearingWalk::kFullWalk;
    VoxelMap full(config);
    config.clearing_walk = ClearingWalk::kBounded;
    config.clearing_mode = ClearingMode::kRaycast;
    VoxelMap raycast(config);
    for (VoxelMap* map : {&ours, &full, &raycast}) map->set_voxels(fill);
    std::vector<double> mark, clear, full_clear, ray_clear, ray_mark, octomap_insert;
    std::optional<OctomapPeer> octomap;
    if (result.have_octomap) octomap.emplace(options.voxel_size_m);
    for (const SyntheticFrame& frame : frames) {
      const std::vector<ClearingObservation> obs = {{frame.T_world_camera, source, &frame.points_W}};
      clear.push_back(time_once_ms([&] { ours.clear(obs, frame.time_s); }));
      mark.push_back(time_once_ms([&] { ours.mark(frame.points_W, frame.T_world_camera, source, frame.time_s); }));
      full_clear.push_back(time_once_ms([&] { full.clear(obs, frame.time_s); }));
      full.mark(frame.points_W, frame.T_world_camera, source, frame.time_s);
      ray_clear.push_back(time_once_ms([&] { raycast.clear(obs, frame.time_s); }));
      ray_mark.push_back(
          time_once_ms([&] { raycast.mark(frame.points_W, frame.T_world_camera, source, frame.time_s); }));
      if (octomap)
        octomap_insert.push_back(
            octomap->insert_ms(frame.points_W, frame.T_world_camera.translation(), kFrameMaxRangeM));
    }
    row.octomap_insert_ms = median(octomap_insert, 0.0);  // 0 without OctoMap
    row.mark_ms = median(mark);
    row.clear_ms = median(clear);
    row.full_walk_clear_ms = median(full_clear);
    row.raycast_clear_ms = median(ray_clear);
    row.raycast_mark_ms = median(ray_mark);
    row.final_voxels = ours.size();
    const auto a = ours.voxels(), b = full.voxels();
    row.full_walk_matches =
        a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](const Voxel& x, const Voxel& y) {
          return x.key == y.key && x.time_s == y.time_s;
        });
    result.rows.push_back(row);
  }

  return result;
}

void print_map_bench(const MapBenchResult& r, std::ostream& out) {
  const auto flags = out.flags();
  out << std::fixed << std::setprecision(3);
  out << "map-bench: voxel_size " << r.options.voxel_size_m << " m, " << r.options.frames << " frames, "
      << std::setprecision(0) << r.points_per_frame << " points/frame (424x240 D435-like, voxel-filtered), seed "
      << r.options.seed << ", " << (r.options.threads > 0 ? std::to_string(r.options.threads) : std::string("all"))
      << " threads\n"
      << "median ms per frame; ratios against the first size in the same run\n\n";
  out << std::setprecision(3);
  out << "| prefilled voxels | mark | clear (ours) | clear (full walk) | full/ours | ours vs first | full vs first "
         "| raycast clear | raycast clear+mark | mark+clear (ours) | same map |\n"
      << "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|:---:|\n";
  const MapBenchRow& first = r.rows.front();
  for (const MapBenchRow& row : r.rows) {
    out << "| " << row.prefilled_voxels << " | " << row.mark_ms << " | " << row.clear_ms << " | "
        << row.full_walk_clear_ms << " | " << std::setprecision(1) << row.full_walk_clear_ms / row.clear_ms << "x | "
        << std::setprecision(2) << row.clear_ms / first.clear_ms << "x | "
        << row.full_walk_clear_ms / first.full_walk_clear_ms << "x | " << std::setprecision(3) << row.raycast_clear_ms
        << " | " << row.raycast_clear_ms + row.raycast_mark_ms << " | " << row.mark_ms + row.clear_ms << " | "
        << (row.full_walk_matches ? "yes" : "NO") << " |\n";
  }
  if (r.have_octomap) {
    out << "\nRay-cast (clear + mark) vs OctoMap OcTree::insertPointCloud on the same clouds, origins, voxel size and "
           "max range (fresh OcTree, interleaved frame by frame):\n\n"
        << "| prefilled voxels | raycast clear+mark | octomap insertPointCloud | speed-up |\n|---:|---:|---:|---:|\n";
    for (const MapBenchRow& row : r.rows) {
      const double ours = row.raycast_clear_ms + row.raycast_mark_ms;
      out << "| " << row.prefilled_voxels << " | " << std::setprecision(3) << ours << " | " << row.octomap_insert_ms
          << " | " << std::setprecision(1) << row.octomap_insert_ms / ours << "x |\n";
    }
  } else {
    out << "\nOctoMap peer not run (liboctomap not found at build time or --no-octomap)\n";
  }
  out.flags(flags);
}

}  // namespace stvl::bench

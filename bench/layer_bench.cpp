#include "bench/layer_bench.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <memory>
#include <ostream>
#include <stdexcept>

#include "bench/synthetic_corridor.hpp"
#include "bench/timing.hpp"
#include "common/statistics.hpp"
#include "layer/layer.hpp"
#include "layer/stvl_layer.hpp"

namespace stvl::bench {
namespace {

constexpr int kZVoxels = 16;  // nav2's grids: 16 levels of voxel_size (nav2_bringup's z_voxels)

// One camera's source for every layer: marking and clearing, STVL's frustum over the frame's 87 x 58 deg and
// 0.2..5 m, nav2's ranges reaching the frame's 5 m.
layer::SourceConfig bench_source() {
  layer::SourceConfig source;
  mapping::ObservationSource& p = source.params;
  p.marking = p.clearing = true;
  p.obstacle_range_m = kFrameMaxRangeM;
  p.min_obstacle_height_m = 0.05;
  p.max_obstacle_height_m = 2.0;
  p.horizontal_fov_rad = kFrameHorizontalFovRad;
  p.vertical_fov_rad = kFrameVerticalFovRad;
  p.min_z_m = kFrameMinRangeM;
  p.max_z_m = kFrameMaxRangeM;
  p.decay_acceleration_per_s3 = 1.0;
  source.nav2.obstacle_max_range_m = kFrameMaxRangeM;
  source.nav2.raytrace_max_range_m = kFrameMaxRangeM;
  return source;
}

// The config of one layer at one map size: STVL's map as it is (pre-filled by the caller), nav2's grids as a
// square rolling window of `size` voxels (columns x 16 levels).
layer::LayerConfig config_of(layer::LayerType type, std::size_t size, int cameras, double voxel_size_m) {
  layer::LayerConfig c;
  c.type = type;
  c.map.voxel_size_m = voxel_size_m;
  for (int i = 0; i < cameras; ++i) {
    layer::SensorConfig sensor;
    sensor.name = "camera" + std::to_string(i);
    sensor.sources = {bench_source()};
    sensor.sources[0].name = sensor.name;
    c.sensors.push_back(sensor);
  }
  if (type != layer::LayerType::kStvl) {
    const double side_cells = std::sqrt(static_cast<double>(size) / kZVoxels);
    c.nav2_costmap.width_m = c.nav2_costmap.height_m = std::max(1.0, std::floor(side_cells)) * voxel_size_m;
    c.nav2_costmap.resolution_m = voxel_size_m;
    c.nav2.z_voxels = kZVoxels;
    c.nav2.z_resolution_m = voxel_size_m;
  }
  return c;
}

// STVL's pre-filled voxels: behind the camera's path (from y = -20 m), 100 along, 100 across, then up.
std::vector<mapping::Voxel> prefill(std::size_t count, double voxel_size_m) {
  std::vector<mapping::Voxel> voxels;
  voxels.reserve(count);
  const int y0 = static_cast<int>(std::floor(-20.0 / voxel_size_m));
  for (std::size_t i = 0; i < count; ++i)
    voxels.push_back(
        {{static_cast<int>((i / 100) % 100) - 50, y0 + static_cast<int>(i % 100), static_cast<int>(i / 10000)}, 0.0});
  return voxels;
}

double p95(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(values.size()))) - 1];
}

}  // namespace

void LayerBenchOptions::validate() const {
  mapping::StvlConfig config;
  config.voxel_size_m = voxel_size_m;
  config.validate();
  if (frames < 1 || frames > 100000)
    throw std::invalid_argument("frames = " + std::to_string(frames) + " must lie in [1, 100000]");
  if (sizes.empty()) throw std::invalid_argument("sizes is empty");
  for (std::size_t s : sizes)
    if (s < 16 || s > 10'000'000)
      throw std::invalid_argument("size = " + std::to_string(s) + " must lie in [16, 10^7]");
  if (cameras.empty()) throw std::invalid_argument("cameras is empty");
  for (int c : cameras)
    if (c < 1 || c > 3) throw std::invalid_argument("cameras = " + std::to_string(c) + " must lie in [1, 3]");
}

LayerBenchResult run_layer_bench(const LayerBenchOptions& options) {
  options.validate();
  LayerBenchResult result;
  result.options = options;
  const int max_cameras = *std::max_element(options.cameras.begin(), options.cameras.end());
  // frames[c][f]: camera c's frame at instant f: the corridor's drive, camera c a few frames further along it (its
  // own noise), posed at the same instant.
  std::vector<std::vector<SyntheticFrame>> frames(static_cast<std::size_t>(max_cameras));
  double points = 0.0;
  for (int c = 0; c < max_cameras; ++c)
    for (int f = 0; f < options.frames; ++f) {
      frames[c].push_back(
          synthetic_corridor_frame(options.seed + static_cast<std::uint64_t>(c), f + 7 * c, options.voxel_size_m));
      if (c == 0) points += static_cast<double>(frames[c].back().points_W.cols());
    }
  result.points_per_frame = points / options.frames;

  for (std::size_t size : options.sizes)
    for (int cameras : options.cameras)
      for (const char* variant : {"stvl", "stvl_full_walk", "nav2_voxel", "nav2_obstacle"}) {
        const std::string name = variant;
        const layer::LayerType type = name == "nav2_voxel"      ? layer::LayerType::kNav2Voxel
                                      : name == "nav2_obstacle" ? layer::LayerType::kNav2Obstacle
                                                                : layer::LayerType::kStvl;
        layer::LayerConfig config = config_of(type, size, cameras, options.voxel_size_m);
        // STVL's own walk visits every voxel at every update; the bench's default (bounded) only the frustum's leaves.
        if (name == "stvl_full_walk") config.map.clearing_walk = mapping::ClearingWalk::kFullWalk;
        std::unique_ptr<layer::Layer> layer = layer::make_layer(config);
        if (auto* stvl = dynamic_cast<layer::StvlLayer*>(layer.get()))
          stvl->set_voxels(prefill(size, options.voxel_size_m));
        std::vector<double> update_ms;
        layer::UpdateReport report;
        for (int f = 0; f < options.frames; ++f) {
          const double time_s = f / 30.0;
          std::vector<layer::SensorNow> now(static_cast<std::size_t>(cameras));
          for (int c = 0; c < cameras; ++c) now[c] = {frames[c][f].T_world_camera, time_s};
          double instant_ms = 0.0;
          for (int c = 0; c < cameras; ++c) {
            auto o = std::make_shared<layer::Observation>();
            o->sensor_index = static_cast<std::size_t>(c);
            o->time_s = time_s;
            o->T_world_camera = frames[c][f].T_world_camera;
            o->T_world_base = Eigen::Translation3d(frames[c][f].T_world_camera.translation().x(),
                                                   frames[c][f].T_world_camera.translation().y(), 0.0) *
                              Eigen::Isometry3d::Identity();
            o->decimated_W = frames[c][f].points_W;
            o->marking_W = frames[c][f].points_W;
            now[c].next_frame_time_s = std::numeric_limits<double>::infinity();  // this camera's frame is taken
            instant_ms += time_once_ms([&] { layer->update(o, now, report); });
          }
          update_ms.push_back(instant_ms);
        }
        LayerBenchRow row;
        row.layer = name;
        row.size = size;
        row.cameras = cameras;
        double sum = 0.0;
        for (double ms : update_ms) sum += ms;
        row.mean_ms = sum / static_cast<double>(update_ms.size());
        row.p95_ms = p95(update_ms);
        row.final_voxels = layer->voxels().size();
        for (std::uint8_t cell : layer->costmap().cells) row.final_lethal_cells += cell == mapping::kCostLethal;
        row.map_mib = static_cast<double>(layer->map_bytes()) / (1024.0 * 1024.0);
        result.rows.push_back(row);
      }
  return result;
}

void print_layer_bench(const LayerBenchResult& r, std::ostream& out) {
  const auto flags = out.flags();
  out << std::fixed << std::setprecision(3);
  out << "layer-bench: voxel_size " << r.options.voxel_size_m << " m, " << r.options.frames << " instants, "
      << std::setprecision(0) << r.points_per_frame << " points/frame per camera (424x240 D435-like, voxel-filtered), "
      << "seed " << r.options.seed << "\n"
      << "ms per update (one per instant: every camera's frame); nav2's grids are square rolling windows of the size "
         "(columns x 16 levels); ratios against STVL in the same row group\n\n"
      << "| map size (voxels) | cameras | layer | mean ms | p95 ms | vs STVL (mean) | voxels at the end | lethal "
         "cells | map MiB |\n|---:|---:|---|---:|---:|---:|---:|---:|---:|\n";
  double stvl_mean = 0.0;
  for (const LayerBenchRow& row : r.rows) {
    if (row.layer == "stvl") stvl_mean = row.mean_ms;
    out << "| " << row.size << " | " << row.cameras << " | " << row.layer << " | " << std::setprecision(3)
        << row.mean_ms << " | " << row.p95_ms << " | " << std::setprecision(2)
        << (stvl_mean > 0 ? row.mean_ms / stvl_mean : 0.0) << "x | " << row.final_voxels << " | "
        << row.final_lethal_cells << " | " << std::setprecision(2) << row.map_mib << " |\n";
  }
  out.flags(flags);
}

}  // namespace stvl::bench

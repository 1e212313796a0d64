#include "run/frame_loop.hpp"

#include <filesystem>

#include "common/stopwatch.hpp"

namespace stvl::run {
namespace {

BagRecorder::MapState map_state(const layer::Layer& layer) {
  return {&layer.voxels(), [&layer] { return layer.costmap(); }, !layer.costmap_needs_voxels()};
}

// The frame's series: every stage, the hooks' and the bag's time, the clouds' sizes and the map's.
void append_series(const pipeline::Frame& f, const layer::UpdateReport& report, const layer::Layer& layer,
                   double hooks_ms, double bag_ms, FrameLoopResult& r) {
  r.path_W.emplace_back(f.T_world_base.translation().head<2>());
  r.times.append(f.times, report);
  if (r.camera_times.size() <= f.camera_index) r.camera_times.resize(f.camera_index + 1);
  r.camera_times[f.camera_index].append(f.times, report);
  r.times.evaluation.push_back(hooks_ms);
  r.times.bag.push_back(bag_ms);
  r.times.frame.push_back(f.times.render_ms + f.times.noise_ms + f.times.cloud_ms + f.times.filter_ms +
                          report.clear_ms + report.mark_ms + hooks_ms + bag_ms);
  r.points_raw.push_back(static_cast<std::size_t>(f.point_count));
  r.points_filtered.push_back(static_cast<std::size_t>(f.observation->marking_W.cols()));
  r.map_voxels.push_back(layer.voxels().size());
  r.frames += 1;
  r.footprint_voxels_cleared += report.footprint_voxels_cleared;
  r.sim_time_s = f.time_s;
}

}  // namespace

FrameLoopResult run_frame_loop(FrameSource& source, layer::Layer& layer, FrameHooks& hooks,
                               const FrameLoopSettings& settings) {
  FrameLoopResult r;
  r.camera_times.resize(source.cameras().size());
  std::unique_ptr<BagRecorder> bag;
  if (!settings.bag_path.empty()) bag = source.open_bag(settings.bag_path, settings.bag, nullptr);
  MapPublishClock publish(settings.publish_period_s, settings.publish_grid);
  layer::UpdateReport report;
  const auto wall_start = SteadyClock::now();
  while (const pipeline::Frame* frame = source.next()) {
    const pipeline::Frame& f = *frame;
    if (settings.stop_requested && settings.stop_requested->load()) {
      r.interrupted = true;
      break;
    }
    if (!f.robot_upright) {
      r.fell = true, r.fell_at_s = f.time_s;
      break;
    }
    hooks.before_update(f, layer);
    layer.update(f.observation, f.cameras_now, report);
    hooks.after_update(f, report, layer);
    const auto bag_start = SteadyClock::now();
    if (!settings.bag_path.empty() && !bag) bag = source.open_bag(settings.bag_path, settings.bag, &f);
    // The map goes into the bag after an update (with several cameras at one instant: after the last of them).
    const bool publish_map =
        settings.publish_after_updates_only ? report.map_updated() && publish.due(f.time_s) : publish.due(f.time_s);
    if (bag) hooks.before_bag(*bag, f);
    if (bag) bag->record(f, report, source.cameras(), map_state(layer), publish_map);
    append_series(f, report, layer, hooks.last_frame_ms(), ms_since(bag_start), r);
    if (hooks.done(f, report, r.frames)) break;
  }
  r.wall_time_s = s_since(wall_start);
  r.real_time_factor = r.wall_time_s > 0 ? r.sim_time_s / r.wall_time_s : 0;
  r.sources = layer.source_status(r.sim_time_s);
  if (r.interrupted) return r;  // the bag stays as <bag>.active
  if (bag) {
    // The bag ends with the final map, the one map.vdb and costmap.pgm hold.
    if (r.frames > 0 && publish.final_due(r.sim_time_s)) bag->record_map(r.sim_time_s, map_state(layer));
    bag->close();
  }
  return r;
}

void write_layer_outputs(const layer::Layer& layer, const std::string& out_dir) {
  if (out_dir.empty()) return;
  const std::filesystem::path out = out_dir;
  layer.voxels().save_vdb((out / "map.vdb").string());
  layer.voxels().save_ply((out / "map.ply").string());
  if (map_state(layer).has_costmap()) mapping::write_costmap(layer.costmap(), (out / "costmap").string());
  if (const layer::Nav2Costmap* master = layer.master())
    mapping::write_costmap(master->master(), (out / "nav2_costmap").string());
}

}  // namespace stvl::run

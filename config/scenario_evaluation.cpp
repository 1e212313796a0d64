// The scenario's `evaluation` and `checks` sections (scenario_detail.hpp).
#include <cmath>

#include "config/scenario_detail.hpp"
#include "config/yaml_reader.hpp"

namespace stvl::config::scenario_detail {

void read_evaluation(YamlMap e, Scenario& s) {
  auto& ev = s.evaluation;
  e.get("recall_window_s", ev.recall_window_s);
  e.get("evaluate_every_s", ev.evaluate_every_s);
  e.get("tolerance_voxels", ev.tolerance_voxels);
  e.get("min_observed_voxels", ev.min_observed_voxels);
  e.get("phantom_min_cells", ev.phantom_min_cells);
  e.get("phantom_clearance_m", ev.phantom_clearance_m);
  e.get("path_corridor_m", ev.path_corridor_m);
  e.get("sample_depth_frames", s.outputs.sample_depth_frames);
  e.get("soak_sample_every_s", s.outputs.soak_sample_every_s);
  e.finish();
  require_range(e, "soak_sample_every_s", s.outputs.soak_sample_every_s,
                std::isfinite(s.outputs.soak_sample_every_s) && s.outputs.soak_sample_every_s >= 0,
                "must be finite and >= 0 s");
  require_range(e, "recall_window_s", ev.recall_window_s, std::isfinite(ev.recall_window_s) && ev.recall_window_s > 0,
                "must be finite and > 0 s");
  require_range(e, "evaluate_every_s", ev.evaluate_every_s,
                std::isfinite(ev.evaluate_every_s) && ev.evaluate_every_s > 0, "must be finite and > 0 s");
  require_range(e, "tolerance_voxels", ev.tolerance_voxels, ev.tolerance_voxels >= 0 && ev.tolerance_voxels <= 3,
                "must lie in 0..3");
  require_range(e, "min_observed_voxels", ev.min_observed_voxels, ev.min_observed_voxels >= 1, "must be >= 1");
  require_range(e, "phantom_min_cells", ev.phantom_min_cells, ev.phantom_min_cells >= 1, "must be >= 1");
  require_range(e, "path_corridor_m", ev.path_corridor_m,
                std::isfinite(ev.path_corridor_m) && ev.path_corridor_m >= 0 && ev.path_corridor_m <= 5,
                "must lie in [0, 5] m");
  require_range(e, "phantom_clearance_m", ev.phantom_clearance_m,
                std::isfinite(ev.phantom_clearance_m) && ev.phantom_clearance_m >= 0 && ev.phantom_clearance_m <= 1,
                "must lie in [0, 1] m");
  require_range(e, "sample_depth_frames", s.outputs.sample_depth_frames,
                s.outputs.sample_depth_frames >= 0 && s.outputs.sample_depth_frames <= 100, "must lie in 0..100");
}

void read_checks(YamlMap c, Scenario& s) {
  auto& ch = s.checks;
  const std::pair<const char*, std::optional<double>*> fractions[] = {
      {"f1_3d_min", &ch.f1_3d_min},
      {"iou_3d_min", &ch.iou_3d_min},
      {"costmap_precision_min", &ch.costmap_precision_min},
      {"costmap_recall_min", &ch.costmap_recall_min},
      {"camera_recall_min", &ch.camera_recall_min}};
  for (const auto& [key, value] : fractions) {
    get_optional(c, key, *value);
    if (*value) require_range(c, key, **value, **value >= 0.0 && **value <= 1.0, "must lie in [0, 1]");
  }
  c.get("all_obstacles_detected", ch.all_obstacles_detected);
  c.get("navigation_success", ch.navigation_success);
  // Counts allowed at most (phantoms, cells, voxels).
  const std::pair<const char*, std::optional<int>*> counts[] = {
      {"phantom_obstacles_max", &ch.phantom_obstacles_max},
      {"costmap_ghosts_max", &ch.costmap_ghosts_max},
      {"outage_cleared_max", &ch.outage_cleared_max},
      {"hidden_false_clears_max", &ch.hidden_false_clears_max},
      {"self_lethal_cells_max", &ch.self_lethal_cells_max},
      {"path_free_lethal_max", &ch.path_free_lethal_max},
      {"collisions_max", &ch.collisions_max},
      {"recoveries_max", &ch.recoveries_max}};
  for (const auto& [key, value] : counts) {
    get_optional(c, key, *value);
    if (*value) require_range(c, key, **value, **value >= 0, "must be >= 0");
  }
  // Times allowed at most.
  const std::pair<const char*, std::optional<double>*> durations[] = {
      {"clearing_latency_max_s", &ch.clearing_latency_max_s},
      {"outage_resume_max_s", &ch.outage_resume_max_s},
      {"time_to_goal_max_s", &ch.time_to_goal_max_s},
      {"blocked_time_max_s", &ch.blocked_time_max_s}};
  for (const auto& [key, value] : durations) {
    get_optional(c, key, *value);
    if (*value) require_range(c, key, **value, std::isfinite(**value) && **value >= 0, "must be finite and >= 0 s");
  }
  get_optional(c, "accuracy_p90_max_m", ch.accuracy_p90_max_m);
  if (ch.accuracy_p90_max_m)
    require_range(c, "accuracy_p90_max_m", *ch.accuracy_p90_max_m,
                  std::isfinite(*ch.accuracy_p90_max_m) && *ch.accuracy_p90_max_m > 0, "must be finite and > 0 m");
  if (ch.self_lethal_cells_max && s.pipeline.map.footprint_B.empty())
    c.fail(c.raw("self_lethal_cells_max"), "self_lethal_cells_max",
           "needs the robot's footprint (map.robot_radius or map.footprint)");

  // The drive's checks judge a closed loop.
  for (const char* key :
       {"navigation_success", "collisions_max", "time_to_goal_max_s", "recoveries_max", "blocked_time_max_s"})
    if (c.has(key) && s.navigation.mode != navigation::NavigationMode::kClosedLoop)
      c.fail(c.raw(key), key, "judges a drive: needs navigation.mode closed_loop");

  for (const auto& [key, value] :
       {std::pair<const char*, std::optional<double>*>{"soak_rss_growth_max", &ch.soak_rss_growth_max},
        {"soak_map_ms_growth_max", &ch.soak_map_ms_growth_max}}) {
    get_optional(c, key, *value);
    if (!*value) continue;
    require_range(c, key, **value, std::isfinite(**value) && **value >= 0, "must be finite and >= 0");
    require_range(c, key, "no samples", s.outputs.soak_sample_every_s > 0, "needs evaluation.soak_sample_every_s > 0");
    require_range(c, key, "no laps", s.pipeline.path.loop, "needs robot.loop: true (it compares with the first lap)");
  }
  c.finish();
}

}  // namespace stvl::config::scenario_detail

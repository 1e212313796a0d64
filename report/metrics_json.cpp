// metrics.json of a run: every figure, section by section (report.hpp).
#include "report/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "common/atomic_file.hpp"
#include "common/format.hpp"
#include "common/markup.hpp"
#include "report/machine.hpp"
#include "report/raster.hpp"
#include "report/report_page.hpp"
#include "report/report_sections.hpp"
#include "run/bag_recorder.hpp"
#include "sim/urdf_robot.hpp"

namespace stvl::report {

using config::Scenario;

nlohmann::json stage_stats(std::vector<double> ms) {
  if (ms.empty()) return {{"mean", 0.0}, {"p50", 0.0}, {"p95", 0.0}};
  const double mean = mean_of(ms);
  std::sort(ms.begin(), ms.end());
  const auto at = [&](double q) {
    return ms[std::min(ms.size() - 1, static_cast<std::size_t>(q * (ms.size() - 1) + 0.5))];
  };
  return {{"mean", mean}, {"p50", at(0.5)}, {"p95", at(0.95)}};
}

nlohmann::json phases_json(const evaluation::PhaseTimes& p) {
  const double frames = std::max<double>(1.0, static_cast<double>(p.frames));
  nlohmann::json j = {{"frames", p.frames}, {"evaluations", p.evaluations}};
  for (const auto& [name, ms] : {std::pair<const char*, double>{"observe", p.observe_ms},
                                 {"clearing", p.clearing_ms},
                                 {"truth_update", p.truth_ms},
                                 {"mapped", p.mapped_ms},
                                 {"observed", p.observed_ms},
                                 {"costmap", p.costmap_ms},
                                 {"phantoms", p.phantoms_ms}})
    j[name] = {{"total", ms}, {"per_frame", ms / frames}};
  return j;
}

namespace {

nlohmann::json mean_figures_json(const evaluation::EvaluationMean& m);

nlohmann::json snapshot_json(const evaluation::EvaluationSnapshot& s) {
  return {{"time_s", s.time_s},
          {"mapped_voxels", s.mapped_voxels},
          {"observed_truth_voxels", s.observed_truth_voxels},
          {"precision", s.precision},
          {"recall", s.recall},
          {"f1", s.f1},
          {"iou", s.iou},
          {"lethal_cells", s.lethal_cells},
          {"costmap_precision", s.costmap_precision},
          {"costmap_recall", s.costmap_recall},
          {"phantom_obstacles", s.phantom_obstacles},
          {"lethal_without_voxels", s.projection.lethal_without_voxels},
          {"columns_without_lethal", s.projection.columns_without_lethal},
          {"self_lethal_inside", s.self_marking.inside},
          {"self_lethal_ring", s.self_marking.ring},
          {"path_free_lethal", s.path_block.cells}};
}

// The means over the run; phantom_obstacles is the mean count, max_phantom_obstacles the most at one snapshot.
// Without a snapshot to average ("evaluated": false) the averaged figures are null: not evaluated, not zero.
nlohmann::json mean_json(const evaluation::EvaluationMean& m) {
  nlohmann::json j = mean_figures_json(m);
  j["evaluated"] = m.snapshots > 0;
  if (m.snapshots == 0)
    for (const char* key : {"precision", "recall", "f1", "iou", "costmap_precision", "costmap_recall",
                            "phantom_obstacles", "mapped_voxels", "observed_truth_voxels", "lethal_cells"})
      j[key] = nullptr;
  const auto& block = m.max_path_block;
  j["max_path_free_lethal"] = block.cells;
  j["max_path_free_lethal_at"] = {{"time_s", m.max_path_block_time_s},
                                  {"first_x_m", block.first_x_m},
                                  {"first_y_m", block.first_y_m},
                                  {"first_along_m", block.first_along_m}};
  return j;
}

nlohmann::json mean_figures_json(const evaluation::EvaluationMean& m) {
  return {{"time_s", m.time_s},
          {"snapshots", m.snapshots},
          {"empty_snapshots", m.empty_snapshots},
          {"mapped_voxels", m.mapped_voxels},
          {"observed_truth_voxels", m.observed_truth_voxels},
          {"precision", m.precision},
          {"recall", m.recall},
          {"f1", m.f1},
          {"iou", m.iou},
          {"lethal_cells", m.lethal_cells},
          {"costmap_precision", m.costmap_precision},
          {"costmap_recall", m.costmap_recall},
          {"phantom_obstacles", m.phantom_obstacles},
          {"max_phantom_obstacles", m.max_phantom_obstacles},
          {"max_lethal_without_voxels", m.max_lethal_without_voxels},
          {"max_columns_without_lethal", m.max_columns_without_lethal}};
}

// Totals over the run in ms, and per frame.

// The final snapshot also says where its phantoms are.
nlohmann::json final_json(const evaluation::EvaluationSnapshot& s) {
  nlohmann::json j = snapshot_json(s);
  j["phantoms"] = nlohmann::json::array();
  for (const evaluation::Phantom& p : s.phantoms)
    j["phantoms"].push_back({{"x_m", p.x_m}, {"y_m", p.y_m}, {"cells", p.cells}});
  return j;
}

// filter.type is what runs on the cloud: "passthrough" where there is no decimation but the marking band's
// passthrough (STVL's default `filter`, issue 31: it said "none"); "decimation" the voxel grid or CSNB alone.
nlohmann::json filter_json(const filter::FilterConfig& f, const std::string& device) {
  const bool pass = f.passthrough_enabled || f.type == filter::FilterType::kPassthrough;
  const bool decimates = f.type == filter::FilterType::kVoxel || f.type == filter::FilterType::kCsnb;
  nlohmann::json j = {{"type", decimates ? filter::to_string(f.type)
                               : pass    ? "passthrough"
                                         : "none"},
                      {"device", device},
                      {"decimation", decimates ? filter::to_string(f.type) : "none"},
                      {"passthrough", pass}};
  if (pass) j["passthrough_band_m"] = {f.passthrough.min_z_m, f.passthrough.max_z_m};
  return j;
}

// The map's STVL parameters (STVL's key names; decay_model as STVL's integer code) and which of our options ran.
// map: the layer's type, STVL's keys (the grid's resolution for nav2's layers) and nav2's layer keys (null for STVL).
nlohmann::json map_json(const pipeline::PipelineConfig& p) {
  const mapping::StvlConfig& m = p.map;
  nlohmann::json footprint = nlohmann::json::array();
  for (const auto& xy : m.footprint_B) footprint.push_back({xy.x(), xy.y()});
  nlohmann::json nav2;
  if (p.layer_type != layer::LayerType::kStvl) {
    const layer::Nav2LayerParams& n = p.nav2_layer;
    nav2 = {{"z_voxels", n.z_voxels},
            {"z_resolution", n.z_resolution_m},
            {"origin_z", n.origin_z_m},
            {"unknown_threshold", n.unknown_threshold},
            {"mark_threshold", n.mark_threshold},
            {"min_obstacle_height", n.min_obstacle_height_m},
            {"max_obstacle_height", n.max_obstacle_height_m},
            {"combination_method", n.combination_method},
            {"footprint_clearing_enabled", n.footprint_clearing_enabled},
            {"nav2_marking_range", layer::to_string(n.marking_range)}};
  }
  return {{"layer_type", layer::to_string(p.layer_type)},
          {"nav2_layer", nav2},
          {"voxel_size", m.voxel_size_m},
          {"voxel_decay", m.voxel_decay_s},
          {"decay_model", static_cast<int>(m.decay_model)},
          {"mark_threshold", m.mark_threshold},
          {"update_frequency", m.update_frequency_hz},
          {"clearing_mode", mapping::to_string(m.clearing_mode)},
          {"mark_rounding", mapping::to_string(m.mark_rounding)},
          {"frustum_geometry", mapping::to_string(m.frustum_geometry)},
          {"update_grouping", mapping::to_string(m.update_grouping)},
          {"costmap_band", mapping::to_string(m.costmap_band)},
          {"costmap_timing", mapping::to_string(m.costmap_timing)},
          {"update_footprint_enabled", m.update_footprint_enabled},
          {"footprint", footprint}};
}

// evaluation.failure_modes.occlusion: occluded obstacles erased (STVL #134); null times: never.
nlohmann::json occlusion_json(const evaluation::OcclusionResult& o) {
  const auto time = [](const std::optional<double>& t) { return t ? nlohmann::json(*t) : nlohmann::json(); };
  nlohmann::json bodies = nlohmann::json::array();
  for (const auto& b : o.bodies)
    bodies.push_back({{"name", b.name},
                      {"hidden_false_clears", b.hidden_false_clears},
                      {"first_s", b.first_s},
                      {"last_s", b.last_s},
                      {"vanished_s", time(b.vanished_s)}});
  return {{"hidden_false_clears", o.hidden_false_clears},
          {"behind_surface", o.behind_surface},
          {"out_of_view", o.out_of_view},
          {"first_s", time(o.first_s)},
          {"bodies", bodies}};
}

// The robot marking itself (STVL issue #214): lethal cells inside its footprint and in the ring around it.
nlohmann::json self_marking_json(const RunResult& r) {
  const auto& map = r.scenario.pipeline.map;
  const auto& e = r.evaluation;
  return {{"footprint_points", map.footprint_B.size()},
          {"update_footprint_enabled", map.update_footprint_enabled},
          {"ring_m", evaluation_config(r.scenario).self_ring_m},
          {"max_inside", e.mean.max_self_inside},
          {"max_ring", e.mean.max_self_ring},
          {"max_self_lethal_cells", e.mean.max_self_lethal},
          {"final_inside", e.final.self_marking.inside},
          {"final_ring", e.final.self_marking.ring},
          {"clear_footprint_voxels_below_m", map.clear_footprint_voxels_below_m},
          {"footprint_voxels_cleared", r.footprint_voxels_cleared}};
}

// evaluation.failure_modes.outage: per camera its outages (frames taken inside, the only-seen true voxels that
// left the map, when it marked and when its recall came back) and per source STVL's staleness and re-applied
// readings. Times in seconds of simulated time; -1 for "never".
nlohmann::json outage_json(const RunResult& r) {
  nlohmann::json cameras = nlohmann::json::array();
  for (std::size_t c = 0; c < r.scenario.pipeline.cameras.size(); ++c) {
    nlohmann::json outages = nlohmann::json::array(), sources = nlohmann::json::array();
    for (const auto& o : r.outages) {
      if (o.camera_index != c) continue;
      outages.push_back({{"from_s", o.window.from_s},
                         {"to_s", o.window.to_s},
                         {"frames_in_window", o.frames_in_window},
                         {"only_seen_voxels", o.only_seen_voxels},
                         {"cleared", o.cleared},
                         {"first_cleared_s", o.first_cleared_s},
                         {"first_marking_frame_s", o.first_marking_frame_s},
                         {"recall_before", o.recall_before},
                         {"recall_resumed_s", o.recall_resumed_s},
                         {"resume_fraction", evaluation::OutageResult::kResumeFraction}});
    }
    for (const auto& st : r.sources) {
      if (st.camera_index != c) continue;
      nlohmann::json spans = nlohmann::json::array();
      double stale_s = 0.0;
      for (const auto& span : st.stale) {
        spans.push_back({{"from_s", span.from_s}, {"to_s", span.to_s}});
        stale_s += span.to_s - span.from_s;
      }
      sources.push_back({{"source", st.source},
                         {"expected_update_rate_s", st.expected_update_rate_s},
                         {"first_stale_s", st.stale.empty() ? -1.0 : st.stale.front().from_s},
                         {"stale_s", stale_s},
                         {"stale_spans", spans},
                         {"reapplied_readings", st.reapplied_readings},
                         {"max_reapplied_age_s", st.max_reapplied_age_s},
                         {"reapplied_max_distance_m", st.reapplied_max_distance_m}});
    }
    cameras.push_back({{"name", r.scenario.pipeline.cameras[c].name},
                       {"skipped_frames", c < r.skipped_frames.size() ? r.skipped_frames[c] : 0},
                       {"outages", outages},
                       {"sources", sources}});
  }
  return {{"cameras", cameras}};
}

// Cameras with timing (issue 43): per camera its timing settings and what they did, and tf's settings.
nlohmann::json frame_timing_json(const RunResult& r) {
  const pipeline::PipelineConfig& p = r.scenario.pipeline;
  nlohmann::json cameras = nlohmann::json::array();
  for (std::size_t c = 0; c < r.camera_timing.size(); ++c) {
    const run::CameraTimingStats& st = r.camera_timing[c];
    const sensors::CameraTimingConfig& t = p.cameras[c].timing;
    std::size_t dropped = 0;
    for (const auto& [reason, n] : st.dropped) dropped += n;
    cameras.push_back({{"name", p.cameras[c].name},
                       {"latency_mean_s", t.latency_mean_s},
                       {"latency_jitter_s", t.latency_jitter_s},
                       {"stamp", sensors::to_string(t.stamp)},
                       {"stamp_offset_s", t.stamp_offset_s},
                       {"drop_probability", t.drop_probability},
                       {"drop_burst_frames", t.drop_burst_frames},
                       {"captured", st.captured},
                       {"delivered", st.delivered},
                       {"dropped", dropped},
                       {"dropped_by_reason", st.dropped},
                       {"after_end", st.after_end},
                       {"in_flight_at_end", st.captured - st.delivered - dropped - st.after_end},
                       {"mean_delay_s", st.mean_delay_s},
                       {"max_delay_s", st.max_delay_s},
                       {"mean_stamp_error_s", st.mean_stamp_error_s},
                       {"max_stamp_error_s", st.max_stamp_error_s}});
  }
  return {{"tf",
           {{"odom_rate_hz", p.tf.odom_rate_hz},
            {"odom_latency_s", p.tf.odom_latency_s},
            {"transform_tolerance_s", p.tf.transform_tolerance_s},
            {"queue_size", p.tf.queue_size}}},
          {"cameras", cameras}};
}

// robot.urdf: the robot from the URDF, its wheels, the drive used and why, and where the footprint came from.
nlohmann::json urdf_robot_json(const config::Scenario& s) {
  const sim::UrdfRobot& robot = *s.pipeline.urdf_robot;
  return {{"urdf", robot.config.urdf},
          {"name", robot.urdf.name},
          {"base_link", robot.urdf.root},
          {"links", robot.urdf.links.size()},
          {"mass_kg", robot.mass_kg},
          {"wheels",
           {{"left_joint", robot.wheels.left_joint},
            {"right_joint", robot.wheels.right_joint},
            {"radius_m", robot.wheels.radius_m},
            {"track_width_m", robot.wheels.track_width_m},
            {"how", robot.wheels.named ? "named" : "found"}}},
          {"drive", sim::to_string(robot.drive)},
          {"drive_reason", robot.drive_reason},
          {"footprint_source", s.footprint_source},
          {"footprint_points", s.pipeline.map.footprint_B.size()},
          {"notices", robot.notices}};
}

nlohmann::json obstacles_json(const evaluation::EvaluationSummary& e) {
  nlohmann::json obstacles = nlohmann::json::array();
  for (const auto& o : e.obstacles)
    obstacles.push_back({{"name", o.name},
                         {"truth_voxels", o.truth_voxels},
                         {"observed_voxels", o.observed_voxels},
                         {"observed", o.observed},
                         {"detected", o.detected},
                         {"best_recall", o.best_recall}});
  return obstacles;
}

// Recall per camera: the total's definition over the truth voxels each camera saw.
nlohmann::json camera_recall_json(const RunResult& r) {
  const auto& e = r.evaluation;
  nlohmann::json cameras = nlohmann::json::array();
  for (std::size_t c = 0; c < r.scenario.pipeline.cameras.size(); ++c) {
    const bool final_known = c < e.final.cameras.size();
    cameras.push_back({{"name", r.scenario.pipeline.cameras[c].name},
                       {"mean_recall", c < e.mean.camera_recall.size() ? e.mean.camera_recall[c] : 0.0},
                       {"final_recall", final_known ? e.final.cameras[c].recall : 0.0},
                       {"final_observed_truth_voxels", final_known ? e.final.cameras[c].observed_truth_voxels : 0}});
  }
  return cameras;
}

// Stage timings per camera, by camera name.
nlohmann::json camera_timing_json(const RunResult& r) {
  nlohmann::json camera_timing = nlohmann::json::object();
  for (std::size_t c = 0; c < r.scenario.pipeline.cameras.size() && c < r.camera_times.size(); ++c) {
    const auto& ct = r.camera_times[c];
    camera_timing[r.scenario.pipeline.cameras[c].name] = {
        {"frames", ct.render.size()},     {"render", stage_stats(ct.render)}, {"noise", stage_stats(ct.noise)},
        {"cloud", stage_stats(ct.cloud)}, {"filter", stage_stats(ct.filter)}, {"clear", stage_stats(ct.clear)},
        {"mark", stage_stats(ct.mark)}};
  }
  return camera_timing;
}

nlohmann::json truth_json(const evaluation::EvaluationSummary& e) {
  nlohmann::json truth_notes = nlohmann::json::array();
  for (const auto& n : e.truth.notes) truth_notes.push_back({{"geom", n.geom}, {"note", n.note}});
  return {{"exact", e.truth.notes.empty()},
          {"geoms", e.truth.geoms},
          {"mesh_geoms", e.truth.mesh_geoms},
          {"mesh_triangles", e.truth.mesh_triangles},
          {"notes", truth_notes}};
}

nlohmann::json checks_json(const RunResult& r) {
  nlohmann::json checks = nlohmann::json::array();
  for (const auto& c : r.checks)
    checks.push_back(
        {{"name", c.name}, {"passed", c.passed}, {"message", c.message}, {"status", evaluation::check_status(c)}});
  return checks;
}

// metrics.json "evaluation": the scenario's evaluation settings and every figure of the run's evaluation.
nlohmann::json evaluation_json(const RunResult& r) {
  const auto& e = r.evaluation;
  nlohmann::json snapshots = nlohmann::json::array();
  for (const auto& s : e.snapshots) snapshots.push_back(snapshot_json(s));
  return {{"tolerance_voxels", r.scenario.evaluation.tolerance_voxels},
          // false: the layer keeps no voxels (nav2's ObstacleLayer): every 3D figure below is 0 and means nothing
          {"voxels_3d", e.voxels_3d},
          {"costmap_projected", e.costmap_projected},  // false: the projection guard's counts are not measured
          {"recall_window_s", r.scenario.evaluation.recall_window_s},
          {"phantom_clearance_m", r.scenario.evaluation.phantom_clearance_m},
          {"truth", truth_json(e)},
          {"mean", mean_json(e.mean)},
          {"final", final_json(e.final)},
          {"snapshots", snapshots},
          {"obstacles", obstacles_json(e)},
          {"accuracy_m",
           {{"count", e.accuracy.count},
            {"mean", e.accuracy.mean_m},
            {"median", e.accuracy.median_m},
            {"p90", e.accuracy.p90_m},
            {"p99", e.accuracy.p99_m},
            {"max", e.accuracy.max_m}}},
          {"clearing",
           {{"stale_voxels_seen_through", e.clearing.stale_voxels_seen_through},
            {"not_cleared", e.clearing.not_cleared},
            {"max_latency_s", e.clearing.max_latency_s},
            {"mean_latency_s", e.clearing.mean_latency_s},
            {"false_clears", e.false_clears}}},
          {"observed_off_truth_voxels", e.observed_off_truth_voxels},
          {"failure_modes",
           {{"outage", outage_json(r)},
            {"occlusion", occlusion_json(e.occlusion)},
            {"self_marking", self_marking_json(r)}}},
          {"cameras", camera_recall_json(r)}};
}

// metrics.json "timing_ms": every stage's statistics, the evaluation's phases and the stages per camera.
nlohmann::json timing_json(const RunResult& r) {
  const auto& t = r.times;
  return {{"render", stage_stats(t.render)},         {"noise", stage_stats(t.noise)},
          {"cloud", stage_stats(t.cloud)},           {"filter", stage_stats(t.filter)},
          {"clear", stage_stats(t.clear)},           {"mark", stage_stats(t.mark)},
          {"evaluation", stage_stats(t.evaluation)}, {"bag", stage_stats(t.bag)},
          {"frame", stage_stats(t.frame)},           {"evaluation_phases", phases_json(r.evaluation_phases)},
          {"per_camera", camera_timing_json(r)}};
}

// Soak runs (issue #270): voxels in metrics["soak"], resident memory and map cost with the timings.
void add_soak_json(const RunResult& r, nlohmann::json& metrics) {
  nlohmann::json voxels = nlohmann::json::array(), resources = nlohmann::json::array();
  for (const auto& x : r.soak.samples) {
    voxels.push_back({{"t_s", x.t_s}, {"voxels", x.voxels}, {"leaves", x.leaves}});
    resources.push_back({{"t_s", x.t_s}, {"rss_mb", x.rss_mb}, {"map_ms", x.map_ms}, {"map_cpu_ms", x.map_cpu_ms}});
  }
  metrics["soak"] = {
      {"sample_every_s", r.soak.sample_every_s},
      {"laps", r.soak.laps},
      {"first_lap_end_s", r.soak.first_lap_end_s ? nlohmann::json(*r.soak.first_lap_end_s) : nlohmann::json()},
      {"samples", voxels}};
  metrics["timing_ms"]["soak"] = {{"first_lap_map_ms", r.soak.first_lap_map_ms},
                                  {"first_lap_map_cpu_ms", r.soak.first_lap_map_cpu_ms},
                                  {"samples", resources}};
}

}  // namespace

nlohmann::json metrics_json(const RunResult& r) {
  nlohmann::json metrics = {
      {"scenario", r.scenario.name},
      {"scenario_file", r.scenario.file},
      {"seed", r.scenario.pipeline.seed},
      {"passed", r.passed()},
      {"interrupted", r.interrupted},
      {"frames", r.frames},
      {"sim_time_s", r.sim_time_s},
      {"voxel_size_m", r.scenario.pipeline.map.voxel_size_m},
      {"filter", filter_json(r.scenario.pipeline.filter, r.filter_device)},
      {"gl_backend", r.gl_backend},
      {"noise", r.scenario.camera().noise.enabled},
      {"cameras", camera_list_json(r.scenario)},
      {"map", map_json(r.scenario.pipeline)},
      {"nav2_costmap", nav2_json(r)},
      {"evaluation", evaluation_json(r)},
      {"checks", checks_json(r)},
      {"points",
       {{"raw_mean", mean_of(r.points_raw)},
        {"filtered_mean", mean_of(r.points_filtered)},
        {"map_voxels_final", r.map_voxels.empty() ? 0 : r.map_voxels.back()}}},
      {"timing_ms", timing_json(r)},
      {"wall_time_s", r.wall_time_s},
      {"real_time_factor", r.real_time_factor},
      {"machine", machine_json()},
  };
  if (r.scenario.pipeline.urdf_robot) metrics["robot"] = urdf_robot_json(r.scenario);
  if (r.soak.sample_every_s > 0) add_soak_json(r, metrics);
  if (r.drive) metrics["navigation"] = navigation_json(r);
  if (!r.camera_timing.empty()) metrics["frame_timing"] = frame_timing_json(r);
  if (const sim::LocalizationConfig& l = r.scenario.pipeline.sim.localization; l.enabled) {
    const run::LocalizationStats& ls = r.localization;
    metrics["localization"] = {{"rate_hz", l.rate_hz},
                               {"global_frame", l.layer_in_odom ? "odom" : "map"},
                               {"corrections", ls.corrections},
                               {"jumps", ls.jumps},
                               {"readings", ls.readings},
                               {"mean_error_m", ls.mean_error_m},
                               {"max_error_m", ls.max_error_m},
                               {"mean_error_yaw_rad", ls.mean_error_yaw_rad},
                               {"max_error_yaw_rad", ls.max_error_yaw_rad}};
  }
  return metrics;
}

}  // namespace stvl::report

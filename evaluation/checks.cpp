#include "evaluation/checks.hpp"

#include <algorithm>
#include <cmath>

#include "common/units.hpp"

namespace stvl::evaluation {

CheckResult not_evaluated(const std::string& name, const std::string& why) { return {name, false, why, false}; }

const char* check_status(const CheckResult& c) { return !c.evaluated ? "not_evaluated" : c.passed ? "pass" : "fail"; }

namespace {

const char* const kNoMean = "not evaluated: no evaluation after the recall window to average (the run was too short)";
const char* const kNoVoxels = "not evaluated: the layer keeps no voxels (nav2's ObstacleLayer marks cells only)";
const char* const kNotProjected =
    "not evaluated: the layer's costmap is not a projection of voxels (nav2's layers raytrace and mark cells)";

CheckResult at_least(const char* name, const char* what, double value, double min) {
  return {name, value >= min, std::string(what) + " " + fixed(value, 4) + ", required >= " + fixed(min, 4)};
}

// The lowest mean recall of one camera against camera_recall_min (the run averaged at least one evaluation).
CheckResult camera_recall_check(const std::vector<double>& recalls, const std::vector<std::string>& camera_names,
                                double min) {
  std::size_t lowest = 0;
  for (std::size_t i = 1; i < recalls.size(); ++i)
    if (recalls[i] < recalls[lowest]) lowest = i;
  const std::string name = lowest < camera_names.size() ? camera_names[lowest] : "camera " + std::to_string(lowest);
  return recalls.empty() ? CheckResult{"camera_recall", false, "no camera was evaluated"}
                         : at_least("camera_recall", ("lowest mean recall of one camera (" + name + ")").c_str(),
                                    recalls[lowest], min);
}

// The checks of the figures averaged over the evaluations: F1, IoU, costmap precision and recall, camera recall.
void add_mean_checks(const ChecksConfig& c, const EvaluationMean& mean, const std::vector<std::string>& camera_names,
                     bool voxels_3d, std::vector<CheckResult>& r) {
  const bool averaged = mean.snapshots > 0;
  const auto mean_check = [&](const char* name, const char* what, double value, const std::optional<double>& min,
                              bool needs_voxels) {
    if (!min) return;
    if (needs_voxels && !voxels_3d) r.push_back(not_evaluated(name, kNoVoxels));
    else r.push_back(averaged ? at_least(name, what, value, *min) : not_evaluated(name, kNoMean));
  };
  mean_check("f1_3d", "mean 3D F1", mean.f1, c.f1_3d_min, true);
  mean_check("iou_3d", "mean 3D IoU", mean.iou, c.iou_3d_min, true);
  mean_check("costmap_precision", "mean costmap precision", mean.costmap_precision, c.costmap_precision_min, false);
  mean_check("costmap_recall", "mean costmap recall", mean.costmap_recall, c.costmap_recall_min, false);
  if (c.camera_recall_min && !voxels_3d) r.push_back(not_evaluated("camera_recall", kNoVoxels));
  else if (c.camera_recall_min && !averaged) r.push_back(not_evaluated("camera_recall", kNoMean));
  else if (c.camera_recall_min && averaged)
    r.push_back(camera_recall_check(mean.camera_recall, camera_names, *c.camera_recall_min));
}

CheckResult all_obstacles_detected_check(const std::vector<ObstacleResult>& obstacles) {
  std::string missed;
  int observed = 0;
  for (const auto& o : obstacles) {
    observed += o.observed;
    if (o.observed && !o.detected) missed += (missed.empty() ? "" : ", ") + o.name;
  }
  return observed == 0 ? not_evaluated("all_obstacles_detected", "not evaluated: no obstacle was observed")
                       : CheckResult{"all_obstacles_detected", missed.empty(),
                                     missed.empty() ? std::to_string(observed) + " observed obstacles all detected"
                                                    : "missed: " + missed};
}

CheckResult path_free_lethal_check(const EvaluationMean& mean, std::size_t allowed) {
  const PathBlock& worst = mean.max_path_block;
  return {"path_free_lethal", worst.cells <= allowed,
          "at worst " + std::to_string(worst.cells) + " lethal cells where the truth is free along the path" +
              (worst.cells ? " (t = " + fixed(mean.max_path_block_time_s, 1) + " s, the first at (" +
                                 fixed(worst.first_x_m, 2) + ", " + fixed(worst.first_y_m, 2) + ") m, " +
                                 fixed(worst.first_along_m, 2) + " m along the path)"
                           : std::string()) +
              ", allowed " + std::to_string(allowed)};
}

// The checks of the costmap: phantom obstacles, costmap ghosts, the robot marking itself, lethal cells on the path.
void add_costmap_checks(const ChecksConfig& c, const evaluation::EvaluationSummary& e, std::vector<CheckResult>& r) {
  const auto& mean = e.mean;
  if (c.phantom_obstacles_max)
    r.push_back({"phantom_obstacles", e.final.phantom_obstacles <= *c.phantom_obstacles_max,
                 std::to_string(e.final.phantom_obstacles) + " phantom obstacles in the final costmap, allowed " +
                     std::to_string(*c.phantom_obstacles_max)});
  if (c.costmap_ghosts_max && !e.costmap_projected) r.push_back(not_evaluated("costmap_ghosts", kNotProjected));
  if (c.costmap_ghosts_max && e.costmap_projected) {
    const std::size_t ghosts = mean.max_lethal_without_voxels, missing = mean.max_columns_without_lethal;
    const auto allowed = static_cast<std::size_t>(*c.costmap_ghosts_max);
    r.push_back({"costmap_ghosts", ghosts <= allowed && missing <= allowed,
                 "at worst " + std::to_string(ghosts) + " lethal cells without voxels and " + std::to_string(missing) +
                     " columns of voxels without a lethal cell at one evaluation, allowed " + std::to_string(allowed)});
  }
  if (c.self_lethal_cells_max) {
    const auto allowed = static_cast<std::size_t>(*c.self_lethal_cells_max);
    r.push_back({"self_lethal_cells", mean.max_self_lethal <= allowed,
                 "at worst " + std::to_string(mean.max_self_lethal) + " lethal cells on the robot (" +
                     std::to_string(mean.max_self_inside) + " inside its footprint, " +
                     std::to_string(mean.max_self_ring) + " in the ring) at one evaluation, allowed " +
                     std::to_string(allowed)});
  }
  if (c.path_free_lethal_max)
    r.push_back(path_free_lethal_check(mean, static_cast<std::size_t>(*c.path_free_lethal_max)));
}

// The checks of clearing and accuracy: clearing latency, p90 distance to the surface, voxels cleared while hidden.
void add_clearing_checks(const ChecksConfig& c, const evaluation::EvaluationSummary& e, std::vector<CheckResult>& r) {
  if (!e.voxels_3d) {
    for (const auto& [name, set] :
         {std::pair<const char*, bool>{"clearing_latency", c.clearing_latency_max_s.has_value()},
          {"accuracy_p90", c.accuracy_p90_max_m.has_value()},
          {"hidden_false_clears", c.hidden_false_clears_max.has_value()}})
      if (set) r.push_back(not_evaluated(name, kNoVoxels));
    return;
  }
  if (c.clearing_latency_max_s) {
    const auto& cl = e.clearing;
    const bool ok = cl.not_cleared == 0 && cl.max_latency_s <= *c.clearing_latency_max_s;
    r.push_back(
        cl.stale_voxels_seen_through == 0
            ? not_evaluated("clearing_latency", "not evaluated: no stale voxel of a moved body was seen through")
            : CheckResult{"clearing_latency", ok,
                          "max latency " + fixed(cl.max_latency_s, 3) +
                              " s, required <= " + fixed(*c.clearing_latency_max_s, 3) + " s (" +
                              std::to_string(cl.not_cleared) + " never cleared)"});
  }
  if (c.accuracy_p90_max_m)
    r.push_back(e.accuracy.count == 0 ? not_evaluated("accuracy_p90", "not evaluated: no mapped voxel")
                                      : CheckResult{"accuracy_p90", e.accuracy.p90_m <= *c.accuracy_p90_max_m,
                                                    "p90 distance to the true surface " + fixed(e.accuracy.p90_m, 4) +
                                                        " m, required <= " + fixed(*c.accuracy_p90_max_m, 4) + " m"});
  if (c.hidden_false_clears_max) {
    const auto& o = e.occlusion;
    r.push_back({"hidden_false_clears", o.hidden_false_clears <= static_cast<std::size_t>(*c.hidden_false_clears_max),
                 std::to_string(o.hidden_false_clears) + " true voxels cleared while the camera did not see them" +
                     (o.first_s ? " (first at t = " + fixed(*o.first_s, 2) + " s)" : "") + ", allowed " +
                     std::to_string(*c.hidden_false_clears_max)});
  }
}

}  // namespace

std::vector<CheckResult> evaluation_checks(const ChecksConfig& c, const evaluation::EvaluationSummary& e,
                                           const std::vector<std::string>& camera_names) {
  std::vector<CheckResult> r;
  add_mean_checks(c, e.mean, camera_names, e.voxels_3d, r);
  if (c.all_obstacles_detected)
    r.push_back(e.voxels_3d ? all_obstacles_detected_check(e.obstacles)
                            : not_evaluated("all_obstacles_detected", kNoVoxels));
  add_costmap_checks(c, e, r);
  add_clearing_checks(c, e, r);
  return r;
}

std::vector<CheckResult> outage_checks(const ChecksConfig& c, const std::vector<evaluation::OutageResult>& outages,
                                       const std::vector<std::string>& camera_names) {
  std::vector<CheckResult> r;
  const auto name_of = [&](std::size_t i) {
    return i < camera_names.size() ? camera_names[i] : "camera " + std::to_string(i);
  };
  if (c.outage_cleared_max) {
    std::size_t cleared = 0, watched = 0;
    for (const auto& o : outages) cleared += o.cleared, watched += o.only_seen_voxels;
    r.push_back({"outage_cleared", !outages.empty() && cleared <= static_cast<std::size_t>(*c.outage_cleared_max),
                 outages.empty() ? "no camera has an outage"
                                 : std::to_string(cleared) + " of " + std::to_string(watched) +
                                       " true voxels only the stopped cameras had seen left the map during their "
                                       "outages, allowed " +
                                       std::to_string(*c.outage_cleared_max)});
  }
  if (c.outage_resume_max_s) {
    std::string late;
    for (const auto& o : outages) {
      const double after_s = o.recall_resumed_s - o.window.to_s;
      if (o.recall_resumed_s < 0 || after_s > *c.outage_resume_max_s)
        late += (late.empty() ? "" : "; ") + name_of(o.camera_index) + " after [" + fixed(o.window.from_s, 2) + ", " +
                fixed(o.window.to_s, 2) + ") s: " +
                (o.recall_resumed_s < 0 ? std::string("recall never back") : "back after " + fixed(after_s, 2) + " s");
    }
    r.push_back({"outage_resume", !outages.empty() && late.empty(),
                 outages.empty() ? "no camera has an outage"
                 : late.empty()  ? "every stopped camera's recall back to 90 % of its value before within " +
                                      fixed(*c.outage_resume_max_s, 2) + " s of the outage's end"
                                : late + " (allowed " + fixed(*c.outage_resume_max_s, 2) + " s)"});
  }
  return r;
}

std::vector<CheckResult> soak_checks(const ChecksConfig& c, const SoakSeries& soak) {
  std::vector<CheckResult> r;
  if (!c.soak_rss_growth_max && !c.soak_map_ms_growth_max) return r;
  const auto& samples = soak.samples;
  // The sample that closes the first lap: the first one at or after its end.
  std::size_t end_of_lap = samples.size();
  if (soak.first_lap_end_s)
    for (std::size_t i = 0; i < samples.size() && end_of_lap == samples.size(); ++i)
      if (samples[i].t_s + kTimeEpsilon_s >= *soak.first_lap_end_s) end_of_lap = i;
  const std::string too_short =
      !soak.first_lap_end_s
          ? "the first lap was not completed (" + std::to_string(samples.size()) + " samples)"
          : "no sample after the one closing the first lap (t = " + fixed(*soak.first_lap_end_s, 1) + " s)";
  const bool comparable = end_of_lap + 1 < samples.size();
  const auto percent = [](double fraction) { return fixed(100.0 * fraction, 1) + " %"; };
  if (c.soak_rss_growth_max) {
    if (!comparable) {
      r.push_back({"soak_rss_growth", false, too_short});
    } else {
      const SoakSample& base = samples[end_of_lap];
      const auto peak = std::max_element(samples.begin() + static_cast<std::ptrdiff_t>(end_of_lap) + 1, samples.end(),
                                         [](const SoakSample& a, const SoakSample& b) { return a.rss_mb < b.rss_mb; });
      const double growth = base.rss_mb > 0 ? peak->rss_mb / base.rss_mb - 1.0 : INFINITY;
      r.push_back({"soak_rss_growth", growth <= *c.soak_rss_growth_max,
                   "resident memory at most " + fixed(peak->rss_mb, 1) + " MiB (t = " + fixed(peak->t_s, 0) +
                       " s) vs " + fixed(base.rss_mb, 1) +
                       " MiB at the end of the first lap (t = " + fixed(base.t_s, 0) + " s): " + percent(growth) +
                       ", allowed " + percent(*c.soak_rss_growth_max)});
    }
  }
  if (c.soak_map_ms_growth_max) {
    // As many of the last samples as one lap spans, all after the sample that closes the first lap.
    const std::size_t window =
        soak.first_lap_end_s && soak.sample_every_s > 0
            ? std::max<std::size_t>(1, static_cast<std::size_t>(
                                           std::ceil(*soak.first_lap_end_s / soak.sample_every_s - kWholeCountEpsilon)))
            : 1;
    if (!comparable) {
      r.push_back({"soak_map_ms_growth", false, too_short});
    } else if (samples.size() - end_of_lap - 1 < window) {
      r.push_back({"soak_map_ms_growth", false,
                   "fewer samples after the first lap (" + std::to_string(samples.size() - end_of_lap - 1) +
                       ") than one lap spans (" + std::to_string(window) + ")"});
    } else {
      // CPU time: wall-clock ms of the same frames swing by a factor 2 with the load of a shared machine.
      double cpu = 0.0, wall = 0.0;
      for (std::size_t i = samples.size() - window; i < samples.size(); ++i)
        cpu += samples[i].map_cpu_ms, wall += samples[i].map_ms;
      cpu /= static_cast<double>(window), wall /= static_cast<double>(window);
      const double growth = soak.first_lap_map_cpu_ms > 0 ? cpu / soak.first_lap_map_cpu_ms - 1.0 : INFINITY;
      r.push_back({"soak_map_ms_growth", growth <= *c.soak_map_ms_growth_max,
                   "map cost " + fixed(cpu, 3) + " ms CPU per frame over the last " + std::to_string(window) +
                       " samples vs " + fixed(soak.first_lap_map_cpu_ms, 3) + " ms over the first lap: " +
                       percent(growth) + ", allowed " + percent(*c.soak_map_ms_growth_max) + " (wall clock " +
                       fixed(wall, 3) + " vs " + fixed(soak.first_lap_map_ms, 3) + " ms)"});
    }
  }
  return r;
}

CheckResult robot_upright_check(bool upright, double time_s, double tilt_rad) {
  if (upright) return {"robot_upright", true, "the robot stayed upright on the floor"};
  return {
      "robot_upright", false,
      "the robot fell over or left the world at t = " + fixed(time_s, 2) + " s (tilt " + fixed(tilt_rad, 2) + " rad)"};
}

CheckResult path_completed_check(bool completed, double time_s, double duration_s, double cut_short_from_s,
                                 bool required_when_cut_short, const std::string& blocked) {
  if (!completed && cut_short_from_s > 0 && !required_when_cut_short)
    return not_evaluated("path_completed", "not evaluated: the path's end was not reached within " +
                                               fixed(duration_s, 1) +
                                               " s, the run cut short by --duration (the scenario runs " +
                                               fixed(cut_short_from_s, 1) + " s; --require-path fails on it)");
  return {"path_completed", completed,
          completed ? "reached the end of the path at t = " + fixed(time_s, 2) + " s"
                    : "did not reach the end of the path within " + fixed(duration_s, 1) + " s" +
                          (blocked.empty() ? std::string() : ": " + blocked)};
}

std::string blocked_diagnosis(const Eigen::Vector2d& at_W, double since_s, const Eigen::Vector2d& path_end_W,
                              const std::vector<std::string>& touching) {
  std::string text = "blocked at (" + fixed(at_W.x(), 2) + ", " + fixed(at_W.y(), 2) +
                     ") m since t = " + fixed(since_s, 1) + " s, " + fixed((path_end_W - at_W).norm(), 2) +
                     " m short of the path's end, touching ";
  if (touching.empty()) return text + "nothing";
  for (std::size_t i = 0; i < touching.size(); ++i) text += (i ? ", " : "") + touching[i];
  return text;
}

}  // namespace stvl::evaluation

#pragma once
// The pass/fail checks of a scenario, from its thresholds and the evaluation's figures.
#include <string>
#include <vector>

#include "evaluation/evaluator.hpp"
#include "evaluation/outage.hpp"
#include "tools/scenario.hpp"
#include "tools/soak.hpp"

namespace stvl::tools {

struct CheckResult {
  std::string name;
  bool passed = false;
  std::string message;  // value and threshold, or why it failed
};

// One result per threshold the scenario sets (f1_3d, iou_3d, costmap_precision, costmap_recall, camera_recall,
// all_obstacles_detected, phantom_obstacles, costmap_ghosts, clearing_latency, accuracy_p90, hidden_false_clears,
// self_lethal_cells), in that order. camera_names name the cameras by index in messages.
std::vector<CheckResult> evaluation_checks(const ChecksConfig& checks, const evaluation::EvaluationSummary& summary,
                                           const std::vector<std::string>& camera_names = {});

// outage_cleared (the only-seen voxels that left the map during outages, summed) and outage_resume (every
// outage's camera recall back to 90 % of its value before, within the threshold after the outage's end), for
// the thresholds the scenario sets; a threshold with no outage in the scenario fails.
std::vector<CheckResult> outage_checks(const ChecksConfig& checks, const std::vector<evaluation::OutageResult>& outages,
                                       const std::vector<std::string>& camera_names = {});

// soak_rss_growth (max resident memory over the samples after the first lap vs the sample at its end) and
// soak_map_ms_growth (mean per-frame map cost of the last samples spanning one lap vs the first lap's), one
// result per threshold set; each fails, saying why, when the run was too short to compare.
std::vector<CheckResult> soak_checks(const ChecksConfig& checks, const SoakSeries& soak);

// robot_upright: the robot fell over or left the world at fell_at_s (when it did).
CheckResult robot_upright_check(bool upright, double time_s, double tilt_rad);
// path_completed: the path's end reached at time_s, or not within duration_s.
CheckResult path_completed_check(bool completed, double time_s, double duration_s);

// `value` with `decimals` digits after the point ("0.9871").
std::string fixed(double value, int decimals);

}  // namespace stvl::tools

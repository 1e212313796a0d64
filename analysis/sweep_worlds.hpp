#pragma once
// A sweep over many worlds (stvl-bench sweep --worlds): each figure's distribution over the worlds and the share of
// worlds where each check holds, per combination of the other axes, with the worst world and the one command that
// reproduces it.
#include <nlohmann/json.hpp>

#include <string>

namespace stvl::analysis {

// From a collect_sweep() table whose rows carry "world": {"groups": [{"group": "<other axes>", "worlds": n,
// "figures": {name: {"n", "mean", "p5", "p95", "worst", "worst_world", "reproduce"}}, "checks": {name: {"held",
// "evaluated", "share", "first_failing_world", "reproduce"}}}]}. Percentiles by nearest rank; worst is the lowest
// for scores (f1, precision, recall, costmap_precision, real_time_factor) and the highest for counts
// (final_phantoms) and times. Rows without figures (a world that did not run) count as failing every check.
nlohmann::json over_worlds(const nlohmann::json& table);
// That summary as HTML tables (a section of sweep.html).
std::string over_worlds_html(const nlohmann::json& summary);

}  // namespace stvl::analysis

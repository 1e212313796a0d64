#pragma once
// A run's outputs for machines and people: metrics.json, junit.xml (one testcase per check), report.html, one
// self-contained page (its pictures inlined: report_sections.hpp).
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "run/replay.hpp"
#include "run/runner.hpp"

namespace stvl::report {

using run::ReplayResult;
using run::RunResult;

// The mean of per-frame values (0 when empty).
template <class T>
double mean_of(const std::vector<T>& values) {
  double sum = 0.0;
  for (const T& v : values) sum += static_cast<double>(v);
  return values.empty() ? 0.0 : sum / static_cast<double>(values.size());
}
// Mean, p50 and p95 of per-frame milliseconds (zeros when empty).
nlohmann::json stage_stats(std::vector<double> ms);
// The evaluation's wall-clock phases: per phase its total and per-frame milliseconds (metrics.json and --profile).
nlohmann::json phases_json(const evaluation::PhaseTimes& phases);
// Every figure of the run; timings under "timing_ms" (mean, p50, p95 per stage) and "real_time_factor".
nlohmann::json metrics_json(const RunResult& result);
std::string junit_xml(const RunResult& result);
// Where a run's time went: per-stage mean and p95 ms per frame with each stage's share of the frame, then the
// evaluation's phases per frame (`stvl-bench run --profile`).
std::string profile_table(const RunResult& result);
// Writes metrics.json, junit.xml, report.html and its PNGs into out_dir (each atomically).
void write_report(const RunResult& result, const std::filesystem::path& out_dir);

// metrics.json of a replay: the recording, frames, points, valid pixels, the map, the sources and per-stage
// timings; "ground_truth": false and no "evaluation" object.
nlohmann::json replay_metrics_json(const ReplayResult& result);
// Writes metrics.json and report.html (which says plainly that there is no ground truth; the recording, charts,
// the map in 3D, the costmap and the sampled depth frames) into out_dir, each atomically.
void write_replay_report(const ReplayResult& result, const std::filesystem::path& out_dir);

}  // namespace stvl::report

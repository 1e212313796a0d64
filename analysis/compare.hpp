#pragma once
// Two runs side by side (stvl-bench compare): every numeric figure of their metrics.json with its delta, and
// the regressions that rules find. A rule reads "LEFT OP NUMBER" with LEFT one of
//   PATH          the figure in B (the new run)
//   delta(PATH)   B - A
//   ratio(PATH)   B / A (a figure that is 0 in A has no ratio: the rule is then false)
// PATH a dotted path into metrics.json ("evaluation.mean.f1", "timing_ms.filter.mean"), OP one of < <= > >=,
// e.g. "delta(evaluation.mean.f1) < -0.01" or "ratio(timing_ms.frame.p50) > 1.2". A rule that holds is a
// regression. Checks that pass in A and fail in B are regressions too (a check not evaluated is not judged).
// Timing rules (paths under timing_ms, real_time_factor, wall_time_s) are judged only when both runs carry the
// same machine fingerprint (metrics.json "machine"); otherwise they are reported as not judged.
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace stvl::analysis {

struct CompareRule {
  enum class Left { kValue, kDelta, kRatio };
  enum class Op { kLess, kLessEqual, kGreater, kGreaterEqual };
  std::string text;  // as given
  Left left = Left::kValue;
  std::string path;
  Op op = Op::kLess;
  double threshold = 0;
};

// Throws std::invalid_argument quoting the rule for anything that is not "LEFT OP NUMBER".
CompareRule parse_compare_rule(const std::string& text);

// The defaults: F1, precision and recall (mean) down by more than 0.01, costmap precision down by more than
// 0.02, any new phantom (final or at any evaluation), and the filter, clear, mark and whole-frame median (p50)
// times more than 20 % slower (medians: a few slow frames moved clear's mean x1.69 while its median fell). Without
// ground truth (two replays of recordings) only the timing rules.
std::vector<CompareRule> default_compare_rules(bool ground_truth = true);

// A replay's metrics.json (stvl-bench replay: "kind": "replay", no evaluation).
bool is_replay(const nlohmann::json& metrics);

struct MetricDelta {
  std::string path;
  double a = 0, b = 0;
};

struct Regression {
  std::string what;    // the rule's text, or "check NAME"
  std::string detail;  // the figures
};

// Every rule's outcome: "regression", "ok" or "not judged" (a timing rule across machines), with the figures.
struct RuleOutcome {
  std::string rule, status, detail;
};
// A setting that differs between the runs (scenario, seed, voxel size, filter, cameras, machine, ...).
struct ConfigDifference {
  std::string path, a, b;
};

struct Comparison {
  std::string a_name, b_name;                        // what was compared (paths)
  std::vector<ConfigDifference> config_differences;  // shown first: figures of different settings differ anyway
  bool same_machine = false;                         // both fingerprints present and equal: timing rules judged
  std::vector<RuleOutcome> outcomes;                 // one per rule, in order
  std::vector<MetricDelta> metrics;  // every numeric figure in both, in A's order (per-evaluation snapshots aside)
  std::vector<std::string> only_in_a, only_in_b;  // numeric figures in one run only
  std::vector<Regression> regressions;
  bool regressed() const { return !regressions.empty(); }
};

// Throws std::invalid_argument when a rule names a figure that is not a number in both runs.
Comparison compare_metrics(const nlohmann::json& a, const nlohmann::json& b, const std::vector<CompareRule>& rules,
                           std::string a_name = "A", std::string b_name = "B");

// metrics.json of a run folder or the file itself (a run's or a replay's); throws std::invalid_argument when
// missing or malformed.
nlohmann::json load_metrics(const std::string& run_folder_or_file);

// True for a rule on a timing figure (timing_ms..., real_time_factor, wall_time_s).
bool is_timing_rule(const CompareRule& rule);
// For a pull-request comment: the configuration differences first, then the regressions and the rules not
// judged, the headline figures, then every figure that changed folded in a <details>.
std::string comparison_markdown(const Comparison& c);
// A standalone page with the same content.
std::string comparison_html(const Comparison& c);
// JUnit XML: one testcase per rule (failure: a regression; skipped: not judged) and per check of B judged
// against A.
std::string comparison_junit(const Comparison& c);

}  // namespace stvl::analysis

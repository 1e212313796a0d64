#pragma once
// Two runs side by side (stvl-bench compare): every numeric figure of their metrics.json with its delta, and
// the regressions that rules find. A rule reads "LEFT OP NUMBER" with LEFT one of
//   PATH          the figure in B (the new run)
//   delta(PATH)   B - A
//   ratio(PATH)   B / A (a figure that is 0 in A has no ratio: the rule is then false)
// PATH a dotted path into metrics.json ("evaluation.mean.f1", "timing_ms.filter.mean"), OP one of < <= > >=,
// e.g. "delta(evaluation.mean.f1) < -0.01" or "ratio(timing_ms.frame.mean) > 1.2". A rule that holds is a
// regression. Checks that pass in A and fail in B are regressions too.
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
// 0.02, any new phantom (final or at any evaluation), and the filter, clear, mark and whole-frame mean times
// more than 20 % slower. Without ground truth (two replays of recordings) only the timing rules.
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

struct Comparison {
  std::string a_name, b_name;         // what was compared (paths)
  std::vector<MetricDelta> metrics;   // every numeric figure in both, in A's order (per-evaluation snapshots aside)
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

// For a pull-request comment: the regressions first, then the headline figures, then every figure that changed.
std::string comparison_markdown(const Comparison& c);
// A standalone page with the same content.
std::string comparison_html(const Comparison& c);

}  // namespace stvl::analysis

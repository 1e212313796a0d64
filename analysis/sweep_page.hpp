#pragma once
// The pages of a collected sweep (stvl-bench sweep --collect): sweep.html, readable at a glance (issue 31:
// distinct colours, charts that do not overlap, 4 significant digits, the failing checks named, a link to each
// point's report), and JUnit with one testcase per point.
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace stvl::analysis {

// A Chart.js line chart of `figure` against the first axis's values, one line per combination of the other axes
// (mean over seeds), each in its own colour, as a JSON config.
nlohmann::json chart_config(const nlohmann::json& table, const std::string& figure);
// sweep.html of a collect_sweep() table; `columns` the figures of each row, Chart.js inlined from chart_js_path
// when it exists.
std::string sweep_html(const nlohmann::json& table, const std::vector<std::string>& columns,
                       const std::string& chart_js_path);
// JUnit XML: one testcase per point, a failure naming its failed checks, an error for a point that did not run.
std::string sweep_junit(const nlohmann::json& table);

}  // namespace stvl::analysis

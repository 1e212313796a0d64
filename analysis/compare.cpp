#include "analysis/compare.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <stdexcept>

#include "common/enum_names.hpp"
#include "common/format.hpp"
#include "common/markup.hpp"

namespace stvl::analysis {
namespace {

using Figures = std::vector<std::pair<std::string, double>>;

// Numeric leaves by dotted path; list items that have a "name" are keyed by it ("obstacles[box_1].detected"),
// others by index. Per-evaluation snapshots are left out (a series, not a figure); booleans count as 0 / 1.
void flatten(const nlohmann::json& j, const std::string& path, Figures& out) {
  if (j.is_object()) {
    for (const auto& [key, value] : j.items()) {
      const std::string child = path.empty() ? key : path + "." + key;
      if (child == "evaluation.snapshots") continue;
      flatten(value, child, out);
    }
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i) {
      const bool named = j[i].is_object() && j[i].contains("name") && j[i]["name"].is_string();
      flatten(j[i], path + "[" + (named ? j[i]["name"].get<std::string>() : std::to_string(i)) + "]", out);
    }
  } else if (j.is_number()) {
    out.emplace_back(path, j.get<double>());
  } else if (j.is_boolean()) {
    out.emplace_back(path, j.get<bool>() ? 1.0 : 0.0);
  }
}

std::map<std::string, double> as_map(const Figures& figures) { return {figures.begin(), figures.end()}; }

std::string signed_number(double v) { return (v > 0 ? "+" : "") + general(v); }

bool holds(double left, CompareRule::Op op, double threshold) {
  switch (op) {
    case CompareRule::Op::kLess: return left < threshold;
    case CompareRule::Op::kLessEqual: return left <= threshold;
    case CompareRule::Op::kGreater: return left > threshold;
    case CompareRule::Op::kGreaterEqual: return left >= threshold;
  }
  return false;
}

double figure(const std::map<std::string, double>& figures, const std::string& path, const CompareRule& rule,
              const std::string& run) {
  const auto it = figures.find(path);
  if (it != figures.end()) return it->second;
  std::vector<std::string> names;
  for (const auto& [name, value] : figures) names.push_back(name);
  const std::string hint = nearest_name(path, names);
  throw std::invalid_argument("rule '" + rule.text + "': " + path + " is not a figure of " + run +
                              (hint.empty() ? "" : "; did you mean '" + hint + "'?"));
}

// The figures a reader looks at first.
const char* const kHeadline[] = {"evaluation.mean.f1",
                                 "evaluation.mean.precision",
                                 "evaluation.mean.recall",
                                 "evaluation.mean.costmap_precision",
                                 "evaluation.final.phantom_obstacles",
                                 "evaluation.mean.max_phantom_obstacles",
                                 "evaluation.clearing.false_clears",
                                 "map.voxels",
                                 "map.costmap_lethal_cells",
                                 "timing_ms.filter.mean",
                                 "timing_ms.frame.mean",
                                 "real_time_factor"};

// Markdown table cells must not hold a bare '|'.
std::string cell(const std::string& text) {
  std::string out;
  for (char c : text) out += c == '|' ? "\\|" : std::string(1, c);
  return out;
}

// Rows of (figure, A, B, delta) for the two tables both outputs show.
struct Tables {
  std::vector<std::array<std::string, 4>> headline, changed;
};

Tables tables_of(const Comparison& c) {
  Tables t;
  const auto row = [](const MetricDelta& m) {
    return std::array<std::string, 4>{m.path, general(m.a), general(m.b), signed_number(m.b - m.a)};
  };
  for (const char* path : kHeadline)
    for (const auto& m : c.metrics)
      if (m.path == path) t.headline.push_back(row(m));
  for (const auto& m : c.metrics)
    if (m.a != m.b) t.changed.push_back(row(m));
  return t;
}

// The settings of a run: every leaf (numbers, strings, booleans) under these keys of metrics.json.
const char* const kConfigKeys[] = {"scenario", "scenario_file", "kind",       "recording", "seed",    "voxel_size_m",
                                   "filter",   "filter_device", "gl_backend", "noise",     "cameras", "machine"};

void leaves(const nlohmann::json& j, const std::string& path, std::map<std::string, std::string>& out) {
  if (j.is_object()) {
    for (const auto& [key, value] : j.items()) leaves(value, path.empty() ? key : path + "." + key, out);
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i) leaves(j[i], path + "[" + std::to_string(i) + "]", out);
  } else {
    out[path] = j.is_string() ? j.get<std::string>() : j.dump();
  }
}

std::vector<ConfigDifference> config_differences(const nlohmann::json& a, const nlohmann::json& b) {
  std::map<std::string, std::string> la, lb;
  for (const char* key : kConfigKeys) {
    if (a.contains(key)) leaves(a[key], key, la);
    if (b.contains(key)) leaves(b[key], key, lb);
  }
  for (const char* key : {"tolerance_voxels", "recall_window_s", "phantom_clearance_m"}) {
    if (a.contains("evaluation") && a["evaluation"].contains(key))
      leaves(a["evaluation"][key], std::string("evaluation.") + key, la);
    if (b.contains("evaluation") && b["evaluation"].contains(key))
      leaves(b["evaluation"][key], std::string("evaluation.") + key, lb);
  }
  std::vector<ConfigDifference> out;
  for (const auto& [path, value] : la) {
    const auto it = lb.find(path);
    if (it == lb.end()) out.push_back({path, value, "(absent)"});
    else if (it->second != value) out.push_back({path, value, it->second});
  }
  for (const auto& [path, value] : lb)
    if (!la.count(path)) out.push_back({path, "(absent)", value});
  return out;
}

std::string fingerprint(const nlohmann::json& m) {
  return m.contains("machine") && m["machine"].is_object() ? m["machine"].value("fingerprint", std::string())
                                                           : std::string();
}

}  // namespace

bool is_timing_rule(const CompareRule& rule) {
  return rule.path.rfind("timing_ms.", 0) == 0 || rule.path == "real_time_factor" || rule.path == "wall_time_s";
}

CompareRule parse_compare_rule(const std::string& text) {
  static const std::regex pattern(
      R"(^\s*(?:(delta|ratio)\(\s*([A-Za-z0-9_.\[\]-]+)\s*\)|([A-Za-z0-9_.\[\]-]+))\s*(<=|>=|<|>)\s*([-+]?[0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*$)");
  std::smatch m;
  if (!std::regex_match(text, m, pattern))
    throw std::invalid_argument("--fail-on '" + text +
                                "': expected PATH, delta(PATH) or ratio(PATH), then < <= > or >=, then a number "
                                "(e.g. 'delta(evaluation.mean.f1) < -0.01')");
  CompareRule rule;
  rule.text = text;
  rule.left = m[1] == "delta"   ? CompareRule::Left::kDelta
              : m[1] == "ratio" ? CompareRule::Left::kRatio
                                : CompareRule::Left::kValue;
  rule.path = m[2].matched ? m[2].str() : m[3].str();
  const std::string op = m[4];
  rule.op = op == "<"    ? CompareRule::Op::kLess
            : op == "<=" ? CompareRule::Op::kLessEqual
            : op == ">"  ? CompareRule::Op::kGreater
                         : CompareRule::Op::kGreaterEqual;
  rule.threshold = std::stod(m[5]);
  return rule;
}

std::vector<CompareRule> default_compare_rules(bool ground_truth) {
  std::vector<CompareRule> rules;
  if (ground_truth)
    for (const char* text :
         {"delta(evaluation.mean.f1) < -0.01", "delta(evaluation.mean.precision) < -0.01",
          "delta(evaluation.mean.recall) < -0.01", "delta(evaluation.mean.costmap_precision) < -0.02",
          "delta(evaluation.final.phantom_obstacles) > 0", "delta(evaluation.mean.max_phantom_obstacles) > 0"})
      rules.push_back(parse_compare_rule(text));
  for (const char* text : {"ratio(timing_ms.filter.p50) > 1.2", "ratio(timing_ms.clear.p50) > 1.2",
                           "ratio(timing_ms.mark.p50) > 1.2", "ratio(timing_ms.frame.p50) > 1.2"})
    rules.push_back(parse_compare_rule(text));
  return rules;
}

bool is_replay(const nlohmann::json& metrics) { return metrics.value("kind", std::string()) == "replay"; }

namespace {

using FigureMap = std::map<std::string, double>;

// One rule on both runs: "not judged" (a timing rule across machines), "ok" or "regression" (also in regressions).
void judge_rule(const CompareRule& rule, const FigureMap& ma, const FigureMap& mb, const nlohmann::json& a,
                const nlohmann::json& b, Comparison& c) {
  const double va = figure(ma, rule.path, rule, c.a_name), vb = figure(mb, rule.path, rule, c.b_name);
  if (is_timing_rule(rule) && !c.same_machine) {
    c.outcomes.push_back({rule.text, "not judged",
                          fingerprint(a).empty() || fingerprint(b).empty()
                              ? "a run carries no machine fingerprint"
                              : "measured on different machines (" + fingerprint(a) + " vs " + fingerprint(b) + ")"});
    return;
  }
  double left = vb;
  if (rule.left == CompareRule::Left::kDelta) left = vb - va;
  const bool ratio_of_zero = rule.left == CompareRule::Left::kRatio && va == 0.0;  // no ratio to a zero
  if (rule.left == CompareRule::Left::kRatio && !ratio_of_zero) left = vb / va;
  const std::string detail =
      rule.path + ": " + general(va) + " -> " + general(vb) + " (" +
      (rule.left == CompareRule::Left::kRatio ? (ratio_of_zero ? "no ratio to 0" : "x" + general(left))
                                              : signed_number(vb - va)) +
      ")";
  if (ratio_of_zero || !std::isfinite(left) || !holds(left, rule.op, rule.threshold)) {
    c.outcomes.push_back({rule.text, "ok", detail});
    return;
  }
  c.outcomes.push_back({rule.text, "regression", detail});
  c.regressions.push_back({rule.text, detail});
}

// Checks that passed in A and fail in B; a check not evaluated (status "not_evaluated") is not judged.
void judge_checks(const nlohmann::json& a, const nlohmann::json& b, Comparison& c) {
  const auto judged = [](const nlohmann::json& check) {
    return check.contains("name") && check.contains("passed") && check["passed"].is_boolean() &&
           check.value("status", std::string()) != "not_evaluated";
  };
  std::map<std::string, bool> passed_in_a;
  if (a.contains("checks") && a["checks"].is_array())
    for (const auto& check : a["checks"])
      if (judged(check)) passed_in_a[check["name"].get<std::string>()] = check["passed"].get<bool>();
  if (b.contains("checks") && b["checks"].is_array())
    for (const auto& check : b["checks"]) {
      if (!judged(check) || check["passed"].get<bool>()) continue;
      const auto it = passed_in_a.find(check["name"].get<std::string>());
      if (it != passed_in_a.end() && it->second) {
        c.regressions.push_back({"check " + it->first, check.value("message", std::string())});
        c.outcomes.push_back({"check " + it->first, "regression", check.value("message", std::string())});
      }
    }
}

}  // namespace

Comparison compare_metrics(const nlohmann::json& a, const nlohmann::json& b, const std::vector<CompareRule>& rules,
                           std::string a_name, std::string b_name) {
  Comparison c;
  c.a_name = std::move(a_name);
  c.b_name = std::move(b_name);
  Figures fa, fb;
  flatten(a, "", fa);
  flatten(b, "", fb);
  const auto ma = as_map(fa), mb = as_map(fb);
  for (const auto& [path, value] : fa) {
    const auto it = mb.find(path);
    if (it == mb.end()) c.only_in_a.push_back(path);
    else c.metrics.push_back({path, value, it->second});
  }
  for (const auto& [path, value] : fb)
    if (!ma.count(path)) c.only_in_b.push_back(path);

  c.config_differences = config_differences(a, b);
  c.same_machine = !fingerprint(a).empty() && fingerprint(a) == fingerprint(b);
  for (const auto& rule : rules) judge_rule(rule, ma, mb, a, b, c);
  judge_checks(a, b, c);
  return c;
}

nlohmann::json load_metrics(const std::string& run_folder_or_file) {
  std::filesystem::path path = run_folder_or_file;
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) path /= "metrics.json";
  if (!std::filesystem::is_regular_file(path, error))
    throw std::invalid_argument(run_folder_or_file + ": no metrics.json (not a run folder or a metrics file)");
  std::ifstream in(path);
  try {
    nlohmann::json j = nlohmann::json::parse(in);
    if (!j.is_object() || !(j.contains("evaluation") || is_replay(j)))
      throw std::invalid_argument(path.string() + ": not a stvl-bench metrics.json (no 'evaluation', not a replay's)");
    return j;
  } catch (const nlohmann::json::parse_error& e) {
    throw std::invalid_argument(path.string() + ": malformed JSON: " + e.what());
  }
}

namespace {

std::string machine_line(const Comparison& c) {
  std::size_t not_judged = 0;
  for (const auto& o : c.outcomes) not_judged += o.status == "not judged";
  if (c.same_machine) return "Timing rules judged: both runs carry the same machine fingerprint.";
  if (not_judged == 0) return "Different machines (or no fingerprint): no timing rule to judge.";
  return "Timing rules not judged (" + std::to_string(not_judged) +
         "): the runs do not carry the same machine fingerprint; timings of different machines are reported, not "
         "compared.";
}

}  // namespace

std::string comparison_markdown(const Comparison& c) {
  std::ostringstream md;
  md << "## stvl-bench compare: " << cell(c.a_name) << " -> " << cell(c.b_name) << "\n\n";
  // Settings first: figures of two different configurations differ for that reason alone.
  if (c.config_differences.empty()) {
    md << "Same configuration.\n\n";
  } else {
    const bool fold = c.config_differences.size() > 8;
    md << "### Configuration differences (" << c.config_differences.size() << ")\n\n";
    if (fold) md << "<details><summary>" << c.config_differences.size() << " settings differ</summary>\n\n";
    md << "| setting | A | B |\n|---|---|---|\n";
    for (const auto& d : c.config_differences)
      md << "| " << cell(d.path) << " | " << cell(d.a) << " | " << cell(d.b) << " |\n";
    md << (fold ? "\n</details>\n\n" : "\n");
  }
  md << machine_line(c) << "\n\n";
  if (c.regressions.empty()) {
    md << "No regression.\n\n";
  } else {
    md << "**" << c.regressions.size() << " regression" << (c.regressions.size() == 1 ? "" : "s") << "**\n\n"
       << "| regression | figures |\n|---|---|\n";
    for (const auto& r : c.regressions) md << "| " << cell(r.what) << " | " << cell(r.detail) << " |\n";
    md << "\n";
  }
  const Tables t = tables_of(c);
  md << "### Headline figures\n\n| figure | A | B | delta |\n|---|---:|---:|---:|\n";
  for (const auto& r : t.headline)
    md << "| " << cell(r[0]) << " | " << r[1] << " | " << r[2] << " | " << r[3] << " |\n";
  md << "\n<details><summary>Rules (" << c.outcomes.size()
     << ")</summary>\n\n| rule | outcome | figures |\n|---|---|---|\n";
  for (const auto& o : c.outcomes) md << "| " << cell(o.rule) << " | " << o.status << " | " << cell(o.detail) << " |\n";
  md << "\n</details>\n\n";
  md << t.changed.size() << " of " << c.metrics.size() << " figures differ";
  if (!c.only_in_a.empty() || !c.only_in_b.empty())
    md << "; " << c.only_in_a.size() << " only in A, " << c.only_in_b.size() << " only in B";
  md << ".\n\n";
  if (!t.changed.empty()) {
    md << "<details><summary>Every figure that differs (" << t.changed.size() << ")</summary>\n\n"
       << "| figure | A | B | delta |\n|---|---:|---:|---:|\n";
    for (const auto& r : t.changed)
      md << "| " << cell(r[0]) << " | " << r[1] << " | " << r[2] << " | " << r[3] << " |\n";
    md << "\n</details>\n";
  }
  return md.str();
}

std::string comparison_html(const Comparison& c) {
  std::ostringstream h;
  h << "<!doctype html><html><head><meta charset=\"utf-8\"><title>stvl-bench compare</title><style>"
       "body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}td,th{border:1px solid #ccc;"
       "padding:3px 8px}td.n{text-align:right}.bad{color:#c62828}.ok{color:#1a7f37}summary{cursor:pointer}"
       "</style></head><body>\n";
  h << "<h1>stvl-bench compare</h1><p>A: " << xml_escape(c.a_name) << "<br>B: " << xml_escape(c.b_name) << "</p>\n";
  if (c.config_differences.empty()) {
    h << "<p>Same configuration.</p>\n";
  } else {
    h << "<h2>Configuration differences (" << c.config_differences.size()
      << ")</h2><table><tr><th>setting</th><th>A</th><th>B</th></tr>\n";
    for (const auto& d : c.config_differences)
      h << "<tr><td>" << xml_escape(d.path) << "</td><td>" << xml_escape(d.a) << "</td><td>" << xml_escape(d.b)
        << "</td></tr>\n";
    h << "</table>\n";
  }
  h << "<p>" << xml_escape(machine_line(c)) << "</p>\n";
  if (c.regressions.empty()) {
    h << "<p class=\"ok\">No regression.</p>\n";
  } else {
    h << "<h2 class=\"bad\">" << c.regressions.size() << " regression" << (c.regressions.size() == 1 ? "" : "s")
      << "</h2><table><tr><th>regression</th><th>figures</th></tr>\n";
    for (const auto& r : c.regressions)
      h << "<tr><td>" << xml_escape(r.what) << "</td><td>" << xml_escape(r.detail) << "</td></tr>\n";
    h << "</table>\n";
  }
  const Tables t = tables_of(c);
  const auto table = [&](const auto& rows) {
    h << "<table><tr><th>figure</th><th>A</th><th>B</th><th>delta</th></tr>\n";
    for (const auto& r : rows)
      h << "<tr><td>" << xml_escape(r[0]) << "</td><td class=\"n\">" << r[1] << "</td><td class=\"n\">" << r[2]
        << "</td><td class=\"n\">" << r[3] << "</td></tr>\n";
    h << "</table>\n";
  };
  h << "<h2>Headline figures</h2>";
  table(t.headline);
  h << "<details><summary>Rules (" << c.outcomes.size()
    << ")</summary><table><tr><th>rule</th><th>outcome</th><th>figures</th></tr>\n";
  for (const auto& o : c.outcomes)
    h << "<tr><td>" << xml_escape(o.rule) << "</td><td class=\"" << (o.status == "regression" ? "bad" : "") << "\">"
      << o.status << "</td><td>" << xml_escape(o.detail) << "</td></tr>\n";
  h << "</table></details>\n<p>" << t.changed.size() << " of " << c.metrics.size() << " figures differ.</p>\n";
  if (!t.changed.empty()) {
    h << "<details><summary>Every figure that differs (" << t.changed.size() << ")</summary>";
    table(t.changed);
    h << "</details>\n";
  }
  h << "</body></html>\n";
  return h.str();
}

std::string comparison_junit(const Comparison& c) {
  std::size_t failures = 0, skipped = 0;
  for (const auto& o : c.outcomes) failures += o.status == "regression", skipped += o.status == "not judged";
  std::ostringstream x;
  x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites tests=\"" << c.outcomes.size() << "\" failures=\""
    << failures << "\" skipped=\"" << skipped << "\">\n  <testsuite name=\"compare\" tests=\"" << c.outcomes.size()
    << "\" failures=\"" << failures << "\" skipped=\"" << skipped << "\">\n";
  for (const auto& o : c.outcomes) {
    x << "    <testcase classname=\"stvl-bench.compare\" name=\"" << xml_escape(o.rule) << "\">";
    if (o.status == "regression") x << "<failure message=\"" << xml_escape(o.detail) << "\"/>";
    else if (o.status == "not judged") x << "<skipped message=\"" << xml_escape(o.detail) << "\"/>";
    else x << "<system-out>" << xml_escape(o.detail) << "</system-out>";
    x << "</testcase>\n";
  }
  x << "  </testsuite>\n</testsuites>\n";
  return x.str();
}

}  // namespace stvl::analysis

#include "analysis/sweep_page.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>

#include "analysis/sweep_worlds.hpp"
#include "common/markup.hpp"

namespace stvl::analysis {
namespace {

// Distinct, saturated colours (Okabe-Ito, then Tableau), so that lines are told apart on white.
const char* const kColours[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000",
                                "#4E79A7", "#F28E2B", "#E15759", "#76B7B2", "#59A14F", "#B07AA1", "#9C755F"};

// 4 significant digits; integers as they are.
std::string short_number(const nlohmann::json& v) {
  if (!v.is_number()) return v.is_null() ? "-" : v.dump();
  const double x = v.get<double>();
  if (x == std::round(x) && std::fabs(x) < 1e15) return std::to_string(static_cast<long long>(x));
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", x);
  return text;
}

}  // namespace

nlohmann::json chart_config(const nlohmann::json& table, const std::string& figure) {
  const auto& axes = table["axes"];
  const std::string x_key = axes.empty() ? "seed" : axes[0].get<std::string>();
  std::vector<std::string> labels;
  std::map<std::string, std::map<std::string, std::pair<double, int>>> series;  // line -> x -> (sum, n)
  for (const auto& row : table["rows"]) {
    const std::string x = x_key == "seed" ? row.value("seed", std::string("-")) : row["sets"][x_key].get<std::string>();
    if (std::find(labels.begin(), labels.end(), x) == labels.end()) labels.push_back(x);
    std::string line;
    for (std::size_t a = 1; a < axes.size(); ++a)
      line += (line.empty() ? "" : ", ") + axes[a].get<std::string>() + "=" +
              row["sets"][axes[a].get<std::string>()].get<std::string>();
    if (!row.contains("figures") || !row["figures"].contains(figure) || !row["figures"][figure].is_number()) continue;
    auto& cell = series[line.empty() ? figure : line][x];
    cell.first += row["figures"][figure].get<double>();
    cell.second += 1;
  }
  nlohmann::json datasets = nlohmann::json::array();
  std::size_t colour = 0;
  for (const auto& [line, cells] : series) {
    nlohmann::json data = nlohmann::json::array();
    for (const auto& x : labels) {
      const auto it = cells.find(x);
      data.push_back(it == cells.end() ? nlohmann::json() : nlohmann::json(it->second.first / it->second.second));
    }
    const char* c = kColours[colour++ % std::size(kColours)];
    datasets.push_back({{"label", line},
                        {"data", data},
                        {"borderColor", c},
                        {"backgroundColor", c},
                        {"borderWidth", 2},
                        {"pointRadius", 4}});
  }
  return {{"type", "line"},
          {"data", {{"labels", labels}, {"datasets", datasets}}},
          {"options",
           {{"animation", false},
            {"maintainAspectRatio", false},
            {"layout", {{"padding", 8}}},
            {"plugins",
             {{"title", {{"display", true}, {"text", figure + " (mean over seeds)"}, {"font", {{"size", 15}}}}}}},
            {"scales",
             {{"x", {{"title", {{"display", true}, {"text", x_key}}}}},
              {"y", {{"title", {{"display", true}, {"text", figure}}}}}}}}}};
}

std::string sweep_html(const nlohmann::json& table, const std::vector<std::string>& columns,
                       const std::string& chart_js_path) {
  std::size_t passed = 0, failed = 0, missing = 0;
  for (const auto& row : table["rows"]) {
    const std::string state = row["state"].get<std::string>();
    passed += state == "passed", failed += state == "failed", missing += state == "missing";
  }
  std::ostringstream h;
  h << "<!doctype html><html><head><meta charset=\"utf-8\"><title>stvl-bench sweep</title><style>body{font-family:"
       "sans-serif;margin:2em;color:#222}table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:4px 8px}"
       "td.n{text-align:right;font-variant-numeric:tabular-nums}th{background:#f4f4f4;position:sticky;top:0}"
       ".charts{display:flex;flex-wrap:wrap;gap:2em;margin:1.5em 0}.chart{position:relative;width:min(760px,95vw);"
       "height:380px}.wide{overflow-x:auto;max-width:100%}.passed{color:#1a7f37}.failed{color:#c62828;font-weight:bold}"
       ".missing{color:#8a6d00}</style></head><body>\n<h1>stvl-bench sweep</h1><p>"
    << xml_escape(table["scenario"].get<std::string>()) << ": " << table["rows"].size()
    << " points, <span class=\"passed\">" << passed << " passed</span>, <span class=\"failed\">" << failed
    << " failed</span>, <span class=\"missing\">" << missing << " missing</span>.</p>\n";
  std::ifstream chart_js(chart_js_path);
  if (chart_js) {
    const std::string js((std::istreambuf_iterator<char>(chart_js)), {});
    h << "<div class=\"charts\"><div class=\"chart\"><canvas id=\"f1\"></canvas></div><div class=\"chart\"><canvas "
         "id=\"filter_ms\"></canvas></div></div>\n"
      << "<script>" << js << "</script>\n<script>\nnew Chart(document.getElementById('f1'), "
      << script_safe(chart_config(table, "f1").dump()) << ");\nnew Chart(document.getElementById('filter_ms'), "
      << script_safe(chart_config(table, "filter_ms_mean").dump()) << ");\n</script>\n";
  } else {
    h << "<p>(No charts: " << xml_escape(chart_js_path) << " is not installed; apt install libjs-chart.js.)</p>\n";
  }
  if (table.contains("over_worlds")) h << over_worlds_html(table["over_worlds"]);
  const bool worlds = table.contains("over_worlds");
  h << "<div class=\"wide\"><table><tr><th>point</th>" << (worlds ? "<th>world</th>" : "");
  for (const auto& axis : table["axes"]) h << "<th>" << xml_escape(axis.get<std::string>()) << "</th>";
  h << "<th>seed</th><th>state</th>";
  for (const auto& figure : columns) h << "<th>" << xml_escape(figure) << "</th>";
  h << "</tr>\n";
  for (const auto& row : table["rows"]) {
    const std::string point = row["point"].get<std::string>(), state = row["state"].get<std::string>();
    h << "<tr><td>"
      << (state == "missing" ? xml_escape(point)
                             : "<a href=\"" + xml_escape(point) + "/report.html\">" + xml_escape(point) + "</a>")
      << "</td>";
    if (worlds) h << "<td>" << xml_escape(row.value("world", std::string())) << "</td>";
    for (const auto& axis : table["axes"])
      h << "<td>" << xml_escape(row["sets"].value(axis.get<std::string>(), "")) << "</td>";
    std::string failing;
    for (const auto& c : row.value("failed_checks", nlohmann::json::array()))
      failing += (failing.empty() ? ": " : ", ") + c.value("name", std::string());
    h << "<td>" << row.value("seed", std::string()) << "</td><td class=\"" << state << "\" title=\"";
    for (const auto& c : row.value("failed_checks", nlohmann::json::array()))
      h << xml_escape(c.value("message", std::string())) << "&#10;";
    h << "\">" << state << xml_escape(failing) << "</td>";
    for (const auto& figure : columns)
      h << "<td class=\"n\">"
        << (row.contains("figures") && row["figures"].contains(figure) ? short_number(row["figures"][figure]) : "")
        << "</td>";
    h << "</tr>\n";
  }
  h << "</table></div></body></html>\n";
  return h.str();
}

std::string sweep_junit(const nlohmann::json& table) {
  std::size_t failures = 0, errors = 0;
  for (const auto& row : table["rows"]) failures += row["state"] == "failed", errors += row["state"] == "missing";
  const std::string suite = xml_escape(table.value("scenario", std::string("sweep")));
  std::ostringstream x;
  x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites tests=\"" << table["rows"].size() << "\" failures=\""
    << failures << "\" errors=\"" << errors << "\">\n  <testsuite name=\"sweep." << suite << "\" tests=\""
    << table["rows"].size() << "\" failures=\"" << failures << "\" errors=\"" << errors << "\">\n";
  for (const auto& row : table["rows"]) {
    x << "    <testcase classname=\"stvl-bench.sweep." << suite << "\" name=\""
      << xml_escape(row["point"].get<std::string>()) << "\">";
    if (row["state"] == "missing") {
      x << "<error message=\"the point did not run (no metrics.json; see its .log)\"/>";
    } else if (row["state"] == "failed") {
      std::string names, details;
      for (const auto& c : row.value("failed_checks", nlohmann::json::array())) {
        names += (names.empty() ? "" : ", ") + c.value("name", std::string());
        details += c.value("name", std::string()) + ": " + c.value("message", std::string()) + "\n";
      }
      x << "<failure message=\"failed: " << xml_escape(names.empty() ? "the run" : names) << "\">"
        << xml_escape(details) << "</failure>";
    }
    x << "</testcase>\n";
  }
  x << "  </testsuite>\n</testsuites>\n";
  return x.str();
}

}  // namespace stvl::analysis

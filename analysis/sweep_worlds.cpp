#include "analysis/sweep_worlds.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <utility>
#include <vector>

#include "common/format.hpp"
#include "common/markup.hpp"

namespace stvl::analysis {
namespace {

bool higher_is_worse(const std::string& figure) {
  return figure == "final_phantoms" || figure.size() > 3 && figure.compare(figure.size() - 3, 3, "_ms") == 0 ||
         figure.find("_ms_") != std::string::npos;
}

// The command that makes the world and runs the point.
std::string reproduce(const nlohmann::json& row) {
  const std::string make = row.value("make_world", std::string()), run = row.value("command", std::string());
  return make.empty() ? run : make + " && " + run;
}

std::string group_of(const nlohmann::json& table, const nlohmann::json& row) {
  std::string group;
  for (const auto& axis : table["axes"]) {
    const std::string key = axis.get<std::string>();
    group += (group.empty() ? "" : ", ") + key + "=" + row["sets"].value(key, std::string());
  }
  return group.empty() ? "all" : group;
}

using Rows = std::vector<const nlohmann::json*>;

// The figure and check names of a group's rows, each once, in the order they first appear.
void names_in(const Rows& rows, std::vector<std::string>& figures, std::vector<std::string>& checks) {
  for (const auto* row : rows) {
    const nlohmann::json row_figures = row->value("figures", nlohmann::json::object());
    const nlohmann::json row_checks = row->value("checks", nlohmann::json::object());
    for (const auto& [name, value] : row_figures.items())
      if (std::find(figures.begin(), figures.end(), name) == figures.end()) figures.push_back(name);
    for (const auto& [name, status] : row_checks.items())
      if (std::find(checks.begin(), checks.end(), name) == checks.end()) checks.push_back(name);
  }
}

// A figure over the group's worlds: count, mean, p5, p95 and the worst world; null when no world has it.
nlohmann::json figure_over_worlds(const Rows& rows, const std::string& figure) {
  std::vector<std::pair<double, const nlohmann::json*>> values;
  for (const auto* row : rows)
    if (row->contains("figures") && (*row)["figures"].contains(figure) && (*row)["figures"][figure].is_number())
      values.push_back({(*row)["figures"][figure].get<double>(), row});
  if (values.empty()) return nullptr;
  std::sort(values.begin(), values.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  const auto rank = [&](double q) {
    const std::size_t k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size())));
    return values[std::min(values.size() - 1, k == 0 ? 0 : k - 1)].first;
  };
  double sum = 0;
  for (const auto& v : values) sum += v.first;
  const auto& worst = higher_is_worse(figure) ? values.back() : values.front();
  return {{"n", values.size()},
          {"mean", sum / static_cast<double>(values.size())},
          {"p5", rank(0.05)},
          {"p95", rank(0.95)},
          {"worst", worst.first},
          {"worst_world", worst.second->value("world", std::string())},
          {"reproduce", reproduce(*worst.second)}};
}

// A check over the group's worlds: in how many it held of those that evaluated it, and the first failing world.
nlohmann::json check_over_worlds(const Rows& rows, const std::string& check) {
  std::size_t held = 0, evaluated = 0;
  const nlohmann::json* failing = nullptr;
  for (const auto* row : rows) {
    const nlohmann::json statuses = row->value("checks", nlohmann::json::object());
    const std::string status = statuses.value(check, row->value("state", std::string()) == "missing" ? "fail" : "");
    if (status != "pass" && status != "fail") continue;  // skipped, or not made for this world
    ++evaluated;
    held += status == "pass";
    if (status == "fail" && !failing) failing = row;
  }
  return {{"held", held},
          {"evaluated", evaluated},
          {"share", evaluated ? static_cast<double>(held) / static_cast<double>(evaluated) : 0.0},
          {"first_failing_world", failing ? failing->value("world", std::string()) : ""},
          {"reproduce", failing ? reproduce(*failing) : ""}};
}

}  // namespace

nlohmann::json over_worlds(const nlohmann::json& table) {
  std::map<std::string, Rows> groups;
  std::vector<std::string> order;
  for (const auto& row : table["rows"]) {
    if (!row.contains("world")) continue;
    const std::string g = group_of(table, row);
    if (!groups.count(g)) order.push_back(g);
    groups[g].push_back(&row);
  }
  nlohmann::json out = {{"groups", nlohmann::json::array()}};
  for (const auto& g : order) {
    const auto& rows = groups[g];
    nlohmann::json group = {{"group", g},
                            {"worlds", rows.size()},
                            {"figures", nlohmann::json::object()},
                            {"checks", nlohmann::json::object()}};
    std::vector<std::string> figures, checks;
    names_in(rows, figures, checks);
    for (const auto& figure : figures)
      if (nlohmann::json f = figure_over_worlds(rows, figure); !f.is_null()) group["figures"][figure] = std::move(f);
    for (const auto& check : checks) group["checks"][check] = check_over_worlds(rows, check);
    out["groups"].push_back(group);
  }
  return out;
}

std::string over_worlds_html(const nlohmann::json& summary) {
  std::ostringstream h;
  for (const auto& group : summary["groups"]) {
    h << "<h2>Over " << group["worlds"].get<std::size_t>()
      << " worlds: " << xml_escape(group["group"].get<std::string>())
      << "</h2>\n<div class=\"wide\"><table><tr><th>figure</th><th>worlds</th><th>mean</th><th>p5</th><th>p95</th>"
         "<th>worst</th><th>worst world</th><th>reproduce it</th></tr>\n";
    for (const auto& [name, f] : group["figures"].items())
      h << "<tr><td>" << xml_escape(name) << "</td><td class=\"n\">" << f["n"].get<std::size_t>()
        << "</td><td class=\"n\">" << general(f["mean"].get<double>(), 4) << "</td><td class=\"n\">"
        << general(f["p5"].get<double>(), 4) << "</td><td class=\"n\">" << general(f["p95"].get<double>(), 4)
        << "</td><td class=\"n\">" << general(f["worst"].get<double>(), 4) << "</td><td>"
        << xml_escape(f["worst_world"].get<std::string>()) << "</td><td><code>"
        << xml_escape(f["reproduce"].get<std::string>()) << "</code></td></tr>\n";
    h << "</table></div>\n<div class=\"wide\"><table><tr><th>check</th><th>holds in</th><th>share</th>"
         "<th>first failing world</th><th>reproduce it</th></tr>\n";
    for (const auto& [name, c] : group["checks"].items())
      h << "<tr><td>" << xml_escape(name) << "</td><td class=\"n\">" << c["held"].get<std::size_t>() << " of "
        << c["evaluated"].get<std::size_t>() << "</td><td class=\"n\">" << general(100.0 * c["share"].get<double>(), 4)
        << " %</td><td>" << xml_escape(c["first_failing_world"].get<std::string>()) << "</td><td><code>"
        << xml_escape(c["reproduce"].get<std::string>()) << "</code></td></tr>\n";
    h << "</table></div>\n";
  }
  return h.str();
}

}  // namespace stvl::analysis

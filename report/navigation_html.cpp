// report.html "Closed loop" (issue 41): the drive's figures against the truth, a speed and event chart (its canvas;
// report_page draws it with Chart.js), the tree's events and the planning cycles blocked by phantoms or driving
// into the unseen.
#include <sstream>

#include "common/format.hpp"
#include "common/markup.hpp"
#include "report/report_sections.hpp"

namespace stvl::report {
namespace {

std::string xy(const Eigen::Vector2d& p) { return "(" + fixed(p.x(), 2) + ", " + fixed(p.y(), 2) + ")"; }

}  // namespace

std::string navigation_html(const run::RunResult& r) {
  if (!r.drive) return "";
  const evaluation::DriveSummary& d = *r.drive;
  std::ostringstream h;
  h << "<h2>Closed loop: what the map cost the drive</h2>\n<p>" << xml_escape(d.outcome) << ".</p>\n";
  if (!r.scenario.navigation_findings.empty()) {
    h << "<p>Not modelled in " << xml_escape(r.scenario.navigation_ros_params) << " (what stands in):</p><ul>";
    for (const auto& f : r.scenario.navigation_findings)
      h << "<li>" << xml_escape(config::format_finding(f)) << "</li>";
    h << "</ul>\n";
  }
  h << "<table>"
    << "<tr><th>time to goal</th><th>path</th><th>shortest (truth)</th><th>SPL</th><th>collisions</th>"
    << "<th>min clearance</th><th>stalled</th><th>plans (failed)</th><th>recoveries</th>"
    << "<th>blocked by phantoms</th><th>into the unseen</th></tr>\n<tr><td>"
    << (d.success ? fixed(d.time_to_goal_s, 1) + " s" : "not reached") << "</td><td>" << fixed(d.path_length_m, 2)
    << " m</td><td>" << fixed(d.shortest_truth_m, 2) << " m</td><td>" << fixed(d.spl, 3) << "</td><td>"
    << d.collisions.size() << "</td><td>" << fixed(d.min_clearance_m, 3) << " m</td><td>" << fixed(d.stalled_s, 1)
    << " s</td><td>" << d.plans << " (" << d.plan_failures << ")</td><td>" << d.recoveries << "</td><td>"
    << fixed(d.blocked_time_s, 1) << " s, " << d.blocked_cycles << " cycles</td><td>" << d.unseen_cycles
    << " cycles</td></tr></table>\n";
  h << "<p class=\"legend\">The drive over time: speed (black) and turn rate (grey) from the truth; recoveries, "
       "failures, costmap clearings and the goal as markers (hover for the event); stalls as purple bars, collisions "
       "as dark red crosses.</p>\n<div class=\"chartbox\"><canvas class=\"chart\" id=\"chart-drive\"></canvas></div>\n";
  h << "<details><summary>Events (" << d.events.size() << ")</summary><table><tr><th>t (s)</th><th>event</th>"
    << "<th>detail</th><th>at (m)</th></tr>\n";
  for (const auto& e : d.events)
    if (e.kind != "plan")
      h << "<tr><td>" << fixed(e.time_s, 2) << "</td><td>" << xml_escape(e.kind) << "</td><td>" << xml_escape(e.detail)
        << "</td><td>" << xy(e.at_W) << "</td></tr>\n";
  h << "</table></details>\n";
  std::size_t listed = 0;
  h << "<details><summary>Planning cycles judged against the truth (" << d.attributions.size() << "; "
    << d.blocked_cycles << " blocked, " << d.unseen_cycles << " into the unseen)</summary><table><tr><th>t (s)</th>"
    << "<th>layer's plan</th><th>truth's plan</th><th>verdict</th><th>cells</th></tr>\n";
  for (const auto& a : d.attributions) {
    if (!a.blocked_by_phantoms && !a.into_unseen) continue;
    if (++listed > 200) break;
    h << "<tr><td>" << fixed(a.time_s, 2) << "</td><td>" << (a.layer_found ? fixed(a.layer_length_m, 2) + " m" : "none")
      << "</td><td>" << (a.truth_found ? fixed(a.truth_length_m, 2) + " m" : "none") << "</td><td>"
      << (a.blocked_by_phantoms ? "blocked by phantoms" : "") << (a.into_unseen ? " into the unseen" : "")
      << "</td><td>";
    if (a.blocked_by_phantoms && !a.phantom_cells_W.empty())
      h << a.phantom_cells << " phantom cells, first at " << xy(a.phantom_cells_W.front());
    if (a.into_unseen && !a.unseen_cells_W.empty())
      h << " " << a.unseen_cells << " true lethal cells crossed, first at " << xy(a.unseen_cells_W.front());
    h << "</td></tr>\n";
  }
  h << "</table></details>\n";
  return h.str();
}

}  // namespace stvl::report

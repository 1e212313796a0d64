// metrics.json "navigation" (issue 41): the closed loop's settings that matter to a reader, the drive's figures
// against the truth, its events and the attribution of every planning cycle.
#include "report/report_sections.hpp"

namespace stvl::report {
namespace {

nlohmann::json xy_json(const Eigen::Vector2d& p) { return nlohmann::json::array({p.x(), p.y()}); }

nlohmann::json cells_json(const std::vector<Eigen::Vector2d>& cells) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& c : cells) out.push_back(xy_json(c));
  return out;
}

}  // namespace

nlohmann::json navigation_json(const run::RunResult& r) {
  const navigation::NavigationConfig& c = r.scenario.navigation;
  const evaluation::DriveSummary& d = *r.drive;
  nlohmann::json collisions = nlohmann::json::array(), stalls = nlohmann::json::array(),
                 events = nlohmann::json::array(), cycles = nlohmann::json::array();
  for (const auto& x : d.collisions)
    collisions.push_back({{"t_s", x.time_s}, {"body", x.body}, {"at", xy_json(x.at_W)}});
  for (const auto& x : d.stalls) stalls.push_back({{"from_s", x.from_s}, {"to_s", x.to_s}, {"at", xy_json(x.at_W)}});
  for (const auto& e : d.events)
    if (e.kind != "plan")  // every plan is in planning_cycles
      events.push_back({{"t_s", e.time_s}, {"kind", e.kind}, {"detail", e.detail}, {"at", xy_json(e.at_W)}});
  for (const auto& a : d.attributions)
    cycles.push_back({{"t_s", a.time_s},
                      {"layer_found", a.layer_found},
                      {"layer_length_m", a.layer_length_m},
                      {"truth_found", a.truth_found},
                      {"truth_length_m", a.truth_length_m},
                      {"blocked_by_phantoms", a.blocked_by_phantoms},
                      {"phantom_cells", a.phantom_cells},
                      {"phantom_cells_at", cells_json(a.phantom_cells_W)},
                      {"into_unseen", a.into_unseen},
                      {"unseen_cells", a.unseen_cells},
                      {"unseen_cells_at", cells_json(a.unseen_cells_W)},
                      {"localization_error_m", a.localization_error_m}});
  nlohmann::json stand_ins = nlohmann::json::array();
  for (const auto& f : r.scenario.navigation_findings) stand_ins.push_back(config::format_finding(f));
  return {{"mode", "closed_loop"},
          {"ros_params", r.scenario.navigation_ros_params},
          {"stand_ins", stand_ins},
          {"goal", {c.goal.x_m, c.goal.y_m, c.goal.yaw_rad}},
          {"inscribed_radius_m", c.inscribed_radius_m()},
          {"success", d.success},
          {"outcome", d.outcome},
          {"time_to_goal_s", d.time_to_goal_s},
          {"path_length_m", d.path_length_m},
          {"shortest_truth_m", d.shortest_truth_m},
          {"spl", d.spl},
          {"collisions", collisions},
          {"min_clearance_m", d.min_clearance_m},
          {"stalled_s", d.stalled_s},
          {"stalls", stalls},
          {"plans", d.plans},
          {"plan_failures", d.plan_failures},
          {"recoveries", d.recoveries},
          {"blocked_time_s", d.blocked_time_s},
          {"blocked_cycles", d.blocked_cycles},
          {"unseen_cycles", d.unseen_cycles},
          {"events", events},
          {"timing_ms", {{"navigation", d.navigation_ms}, {"attribution", d.attribution_ms}}},
          {"planning_cycles", cycles}};
}

}  // namespace stvl::report

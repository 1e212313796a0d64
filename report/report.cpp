#include "report/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "common/atomic_file.hpp"
#include "common/format.hpp"
#include "common/markup.hpp"
#include "report/machine.hpp"
#include "report/raster.hpp"
#include "report/report_page.hpp"
#include "report/report_sections.hpp"
#include "run/bag_recorder.hpp"
#include "sim/urdf_robot.hpp"

namespace stvl::report {

using config::Scenario;

std::string profile_table(const RunResult& r) {
  const auto& t = r.times;
  const nlohmann::json frame = stage_stats(t.frame);
  const double frame_mean = frame["mean"].get<double>();
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(2);
  out << "profile: " << r.frames << " frames, " << r.sim_time_s << " s simulated in " << r.wall_time_s
      << " s (real-time factor " << r.real_time_factor << ")\n";
  out << "  stage          mean ms   p95 ms   share of the frame\n";
  for (const auto& [name, ms] : {std::pair<const char*, const std::vector<double>*>{"render", &t.render},
                                 {"noise", &t.noise},
                                 {"cloud", &t.cloud},
                                 {"filter", &t.filter},
                                 {"clear", &t.clear},
                                 {"mark", &t.mark},
                                 {"evaluation", &t.evaluation},
                                 {"bag", &t.bag},
                                 {"frame", &t.frame}}) {
    const nlohmann::json s = stage_stats(*ms);
    char line[128];
    std::snprintf(line, sizeof line, "  %-12s %9.2f %8.2f   %5.1f %%\n", name, s["mean"].get<double>(),
                  s["p95"].get<double>(), frame_mean > 0 ? 100.0 * s["mean"].get<double>() / frame_mean : 0.0);
    out << line;
  }
  const nlohmann::json phases = phases_json(r.evaluation_phases);
  out << "  evaluation phases, ms per frame (" << r.evaluation_phases.evaluations
      << " evaluations; truth_update is also\n"
      << "  counted inside clearing and the evaluate phases; costmap's projection runs beside mapped and observed):\n";
  for (const char* name : {"observe", "clearing", "truth_update", "mapped", "observed", "costmap", "phantoms"}) {
    char line[96];
    std::snprintf(line, sizeof line, "  %-12s %9.2f\n", name, phases[name]["per_frame"].get<double>());
    out << line;
  }
  return out.str();
}

std::string junit_xml(const RunResult& r) {
  int failures = 0, skipped = 0;
  for (const auto& c : r.checks) failures += c.evaluated && !c.passed, skipped += !c.evaluated;
  std::ostringstream x;
  x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    << "<testsuites tests=\"" << r.checks.size() << "\" failures=\"" << failures << "\" skipped=\"" << skipped
    << "\">\n"
    << "  <testsuite name=\"" << xml_escape(r.scenario.name) << "\" tests=\"" << r.checks.size() << "\" failures=\""
    << failures << "\" skipped=\"" << skipped << "\" time=\"" << r.wall_time_s << "\">\n";
  for (const auto& c : r.checks) {
    x << "    <testcase classname=\"stvl-bench." << xml_escape(r.scenario.name) << "\" name=\"" << xml_escape(c.name)
      << "\">";
    if (!c.evaluated) x << "<skipped message=\"" << xml_escape(c.message) << "\"/>";
    else if (c.passed) x << "<system-out>" << xml_escape(c.message) << "</system-out>";
    else x << "<failure message=\"" << xml_escape(c.message) << "\"/>";
    x << "</testcase>\n";
  }
  x << "  </testsuite>\n</testsuites>\n";
  return x.str();
}

namespace {

// report.html's head and title line: scenario, seed, frames, timing, voxel, filter, GL and noise.
void write_page_head(std::ostream& h, const RunResult& r, const nlohmann::json& metrics, const ReportScripts& scripts) {
  h << "<!doctype html><html><head><meta charset=\"utf-8\"><title>stvl-bench: " << xml_escape(r.scenario.name)
    << "</title><style>body{font-family:sans-serif;margin:2em;max-width:1900px}table{border-collapse:collapse}"
       "td,th{border:1px solid #ccc;padding:3px "
       "8px;text-align:left}.pass{color:#1a7f37}.fail{color:#c62828}.skip{color:#8a6d00}"
       "img{max-width:100%;border:1px solid #ddd}"
    << legend_css() << "</style>\n"
    << interactive_head_html(scripts) << "</head><body>\n";
  h << "<h1>" << xml_escape(r.scenario.name) << " <span class=\"" << (r.passed() ? "pass\">PASSED" : "fail\">FAILED")
    << "</span></h1>\n<p>" << xml_escape(r.scenario.file) << ", seed " << r.scenario.pipeline.seed << ", " << r.frames
    << " frames, " << r.sim_time_s << " s simulated in " << r.wall_time_s << " s (real-time factor "
    << r.real_time_factor << "), voxel " << r.scenario.pipeline.map.voxel_size_m << " m, filter "
    << metrics["filter"]["type"].get<std::string>() << " on " << r.filter_device << ", GL " << r.gl_backend
    << ", noise " << (r.scenario.camera().noise.enabled ? "on" : "off") << ".</p>\n";
}

void write_checks_table(std::ostream& h, const RunResult& r) {
  h << "<h2>Checks</h2><table><tr><th>check</th><th>result</th><th>detail</th></tr>\n";
  for (const auto& c : r.checks)
    h << "<tr><td>" << xml_escape(c.name) << "</td><td class=\""
      << (!c.evaluated ? "skip\">not evaluated"
          : c.passed   ? "pass\">pass"
                       : "fail\">FAIL")
      << "</td><td>" << xml_escape(c.message) << "</td></tr>\n";
}

// "Map quality": the mean and final figures, the accuracy and how exact the truth is.
void write_map_quality(std::ostream& h, const RunResult& r) {
  const auto& e = r.evaluation;
  h << "</table>\n<h2>Map quality</h2><p>Tolerance " << r.scenario.evaluation.tolerance_voxels
    << " voxel(s); recall against surfaces seen by the noise-free camera within the last "
    << r.scenario.evaluation.recall_window_s
    << " s.</p><table><tr><th></th><th>precision</th><th>recall</th><th>F1</th>"
       "<th>IoU</th><th>costmap precision</th><th>costmap recall</th><th>phantoms</th></tr>\n";
  const auto row = [&](const char* label, const auto& s, const std::string& phantoms) {
    h << "<tr><td>" << label << "</td><td>" << s.precision << "</td><td>" << s.recall << "</td><td>" << s.f1
      << "</td><td>" << s.iou << "</td><td>" << s.costmap_precision << "</td><td>" << s.costmap_recall << "</td><td>"
      << phantoms << "</td></tr>\n";
  };
  if (e.mean.snapshots > 0)
    row("mean", e.mean,
        fixed(e.mean.phantom_obstacles, 2) + " (at most " + std::to_string(e.mean.max_phantom_obstacles) + ")");
  else
    h << "<tr><td>mean</td><td colspan=\"7\" class=\"skip\">not evaluated: no evaluation after the recall "
         "window</td></tr>\n";
  row("final", e.final, std::to_string(e.final.phantom_obstacles));
  h << "</table><p>Distance of mapped voxel centres to the true surface: mean " << e.accuracy.mean_m << " m, median "
    << e.accuracy.median_m << " m, p90 " << e.accuracy.p90_m << " m, p99 " << e.accuracy.p99_m << " m.</p>\n";
  h << "<p>Truth: " << e.truth.geoms << " obstacle geoms, " << e.truth.mesh_geoms << " of them triangle meshes ("
    << e.truth.mesh_triangles << " triangles), voxelized exactly";
  if (e.truth.notes.empty()) h << ".</p>\n";
  else {
    h << " except:</p><ul>";
    for (const auto& n : e.truth.notes) h << "<li>" << xml_escape(n.note) << "</li>";
    h << "</ul>\n";
  }
}

void write_obstacles_and_clearing(std::ostream& h, const evaluation::EvaluationSummary& e) {
  h << "<h2>Obstacles</h2><table><tr><th>body</th><th>observed</th><th>detected</th><th>best recall</th></tr>\n";
  for (const auto& o : e.obstacles)
    h << "<tr><td>" << xml_escape(o.name) << "</td><td>" << (o.observed ? "yes" : "no") << "</td><td class=\""
      << (o.detected ? "pass\">yes" : (o.observed ? "fail\">MISSED" : "\">-")) << "</td><td>" << o.best_recall
      << "</td></tr>\n";
  h << "</table>\n<h2>Clearing</h2><p>" << e.clearing.stale_voxels_seen_through
    << " stale voxels of moved bodies were seen through; max latency " << e.clearing.max_latency_s << " s, mean "
    << e.clearing.mean_latency_s << " s, " << e.clearing.not_cleared << " never cleared; ray-cast clearing removed "
    << e.false_clears << " true obstacle voxels (false clears).</p>\n";
}

// "Soak" (issue #270): the first lap and the samples' voxels, memory and map cost.
void write_soak_table(std::ostream& h, const RunResult& r) {
  h << "<h2>Soak</h2><p>" << r.soak.laps << " laps; first lap ended at "
    << (r.soak.first_lap_end_s ? fixed(*r.soak.first_lap_end_s, 1) + " s" : std::string("- (not completed)"))
    << ", its map cost " << fixed(r.soak.first_lap_map_ms, 3) << " ms per frame (CPU "
    << fixed(r.soak.first_lap_map_cpu_ms, 3)
    << " ms).</p><table><tr><th>t s</th><th>voxels</th><th>leaves</th><th>resident MiB</th><th>map ms per frame</th>"
       "<th>map CPU ms per frame</th></tr>\n";
  for (const auto& x : r.soak.samples)
    h << "<tr><td>" << fixed(x.t_s, 0) << "</td><td>" << x.voxels << "</td><td>" << x.leaves << "</td><td>"
      << fixed(x.rss_mb, 1) << "</td><td>" << fixed(x.map_ms, 3) << "</td><td>" << fixed(x.map_cpu_ms, 3)
      << "</td></tr>\n";
  h << "</table>\n";
}

}  // namespace

void write_report(const RunResult& r, const std::filesystem::path& out) {
  const nlohmann::json metrics = metrics_json(r);
  write_file_atomically(out / "metrics.json", metrics.dump(2) + "\n");
  write_file_atomically(out / "junit.xml", junit_xml(r));
  const std::string top_down_png = encode_png(top_down_image(r));
  write_file_atomically(out / "top_down.png", top_down_png);
  const ReportScripts scripts = load_report_scripts();

  std::ostringstream h;
  h.precision(4);
  write_page_head(h, r, metrics, scripts);
  write_checks_table(h, r);
  write_map_quality(h, r);
  h << map_contents_html(r);
  h << interactive_body_html(r, scripts);
  h << navigation_html(r);
  h << top_down_html(r, top_down_png, scripts.complete());
  write_obstacles_and_clearing(h, r.evaluation);
  h << failure_modes_html(metrics);
  h << depth_frames_html(r, out);
  h << "\n";
  write_timing_table(h, metrics["timing_ms"]);
  if (!r.soak.samples.empty()) write_soak_table(h, r);
  h << "</body></html>\n";
  write_file_atomically(out / "report.html", h.str());
}

}  // namespace stvl::report

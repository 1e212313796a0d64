#include "report/report_sections.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "common/format.hpp"
#include "common/markup.hpp"
#include "evaluation/checks.hpp"
#include "run/bag_recorder.hpp"

namespace stvl::report {
namespace {

constexpr int kScaleStripPx = 28;  // under the map: the scale bar

// The colours of top_down_image(), named for its legend.
constexpr Rgb kTruth{190, 190, 190}, kMissed{40, 90, 230}, kTrue{30, 160, 60}, kFalse{220, 40, 40}, kPath{0, 0, 0};
// The closed loop's overlays: global plans (every kPlanEvery-th), the goal, recoveries, stalls, collisions.
constexpr Rgb kPlan{120, 180, 255}, kGoal{0, 150, 150}, kRecovery{255, 140, 0}, kStall{150, 0, 200},
    kCollision{110, 0, 0};
constexpr std::size_t kPlanEvery = 5;

std::string css(Rgb c) {
  char text[16];
  std::snprintf(text, sizeof text, "#%02x%02x%02x", c[0], c[1], c[2]);
  return text;
}

std::string swatch(Rgb c, const std::string& label) {
  return "<span class=\"key\"><span class=\"sw\" style=\"background:" + css(c) + "\"></span>" + label + "</span> ";
}

std::string read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

// Lengths of a readable scale bar: the largest 1-2-5 step that fits in a quarter of the width.
double scale_bar_m(double width_m) {
  double bar = 0.1;
  for (double step : {0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0})
    if (step <= width_m / 4) bar = step;
  return bar;
}

struct TopDownGeometry {
  Eigen::AlignedBox2d bounds;
  int scale = 1, map_height = 1;  // pixels per cell; the map's rows above the scale strip
  double px_per_m = 1;
};

TopDownGeometry geometry_of(const run::RunResult& r) {
  TopDownGeometry g;
  const auto& td = r.top_down;
  g.bounds = td.bounds_W;
  for (const auto& p : r.path_W) g.bounds.extend(p);
  if (r.drive) g.bounds.extend(Eigen::Vector2d(r.scenario.navigation.goal.x_m, r.scenario.navigation.goal.y_m));
  if (g.bounds.isEmpty()) g.bounds = Eigen::AlignedBox2d(Eigen::Vector2d(-1, -1), Eigen::Vector2d(1, 1));
  const int cells_x = static_cast<int>(std::ceil(g.bounds.sizes().x() / td.cell_m)) + 2;
  const int cells_y = static_cast<int>(std::ceil(g.bounds.sizes().y() / td.cell_m)) + 2;
  g.scale = std::max(1, std::min(8, 1800 / std::max(cells_x, cells_y)));
  g.map_height = std::max(1, cells_y * g.scale);
  g.px_per_m = g.scale / td.cell_m;
  return g;
}

}  // namespace

std::string legend_css() {
  return ".legend .key{margin-right:1.2em;white-space:nowrap}"
         ".sw{display:inline-block;width:1em;height:1em;border:1px solid #888;vertical-align:middle;margin-right:.3em}"
         ".turbo{display:inline-block;width:14em;height:1em;vertical-align:middle;border:1px solid #888;background:"
         "linear-gradient(90deg,#30123b,#4145ab,#4675ed,#39a2fc,#1bcfd4,#24eca6,#61fc6c,#a4fc3b,#d1e834,#f3c63a,"
         "#fe9b2d,#f36315,#d93806,#b11901,#7a0403)}details{margin:.5em 0}summary{cursor:pointer}";
}

std::string base64(const std::string& bytes) {
  static const char* const kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < 3; ++k) v = v << 8 | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k) out += k <= n ? kAlphabet[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

std::string png_data_uri(const std::string& png_bytes) { return "data:image/png;base64," + base64(png_bytes); }

std::string png_file_data_uri(const std::filesystem::path& png_file) { return png_data_uri(read_bytes(png_file)); }

RgbImage top_down_image(const run::RunResult& r) {
  const auto& td = r.top_down;
  const TopDownGeometry g = geometry_of(r);
  const int cells_x = static_cast<int>(std::ceil(g.bounds.sizes().x() / td.cell_m)) + 2;
  RgbImage image(std::max(1, cells_x * g.scale), g.map_height + kScaleStripPx);
  const int scale = g.scale;
  const auto px = [&](double x) { return static_cast<int>((x - g.bounds.min().x()) / td.cell_m * scale) + scale; };
  const auto py = [&](double y) {
    return g.map_height - 1 - (static_cast<int>((y - g.bounds.min().y()) / td.cell_m * scale) + scale);
  };
  const auto paint = [&](const std::vector<stvl::CellKey>& cells, Rgb color) {
    for (const auto& c : cells) {
      const int x = px(c.x * td.cell_m), y = py((c.y + 1) * td.cell_m);
      image.fill_rect(x, y, x + scale - 1, y + scale - 1, color);
    }
  };
  paint(td.truth, kTruth);
  paint(td.false_negative, kMissed);
  paint(td.true_positive, kTrue);
  paint(td.false_positive, kFalse);
  if (r.drive) {  // closed loop: every few global plans under the driven path, then the events on top
    const auto& plans = r.drive->plan_log;
    for (std::size_t k = 0; k < plans.size(); k += kPlanEvery)
      for (std::size_t i = 1; i < plans[k].path_W.size(); ++i)
        image.line(px(plans[k].path_W[i - 1].x()), py(plans[k].path_W[i - 1].y()), px(plans[k].path_W[i].x()),
                   py(plans[k].path_W[i].y()), kPlan);
  }
  for (std::size_t i = 1; i < r.path_W.size(); ++i)
    image.line(px(r.path_W[i - 1].x()), py(r.path_W[i - 1].y()), px(r.path_W[i].x()), py(r.path_W[i].y()), kPath);
  if (r.drive) {
    const auto mark = [&](const Eigen::Vector2d& p, Rgb color, int half) {
      image.fill_rect(px(p.x()) - half, py(p.y()) - half, px(p.x()) + half, py(p.y()) + half, color);
    };
    const int half = std::max(2, scale);
    const auto& goal = r.scenario.navigation.goal;
    mark({goal.x_m, goal.y_m}, kGoal, half + 1);
    for (const auto& e : r.drive->events)
      if (e.kind == "recovery") mark(e.at_W, kRecovery, half);
    for (const auto& st : r.drive->stalls) mark(st.at_W, kStall, half);
    for (const auto& c : r.drive->collisions) {
      const int x = px(c.at_W.x()), y = py(c.at_W.y()), k = 2 * half;
      image.line(x - k, y - k, x + k, y + k, kCollision);
      image.line(x - k, y + k, x + k, y - k, kCollision);
    }
  }
  // The scale bar under the map, from its left edge: a bar with end ticks, scale_bar_m() long.
  const int bar_px = static_cast<int>(std::lround(scale_bar_m(g.bounds.sizes().x()) * g.px_per_m));
  const int y0 = g.map_height + 10, x0 = 10;
  image.fill_rect(x0, y0, x0 + bar_px, y0 + 3, kPath);
  image.fill_rect(x0, y0 - 6, x0 + 1, y0 + 9, kPath);
  image.fill_rect(x0 + bar_px - 1, y0 - 6, x0 + bar_px, y0 + 9, kPath);
  return image;
}

std::string top_down_html(const run::RunResult& r, const std::string& png_bytes, bool zoom) {
  const TopDownGeometry g = geometry_of(r);
  std::ostringstream h;
  h << "<h2>Top-down: truth vs map</h2>";
  if (zoom) h << "<p>Zoom <input type=\"range\" id=\"topdown-zoom\" min=\"1\" max=\"8\" step=\"0.5\" value=\"1\"></p>";
  h << "<p class=\"legend\">" << swatch(kTrue, "lethal, on a true obstacle")
    << swatch(kFalse, "lethal where the truth is free") << swatch(kMissed, "obstacle seen but not lethal")
    << swatch(kTruth, "true footprint (not seen)") << swatch(kPath, "the robot's path");
  if (r.drive)
    h << swatch(kPlan, "global plans (every " + std::to_string(kPlanEvery) + "th)") << swatch(kGoal, "goal")
      << swatch(kRecovery, "recoveries") << swatch(kStall, "stalls") << swatch(kCollision, "collisions (cross)");
  h << "</p>\n";
  h << "<div style=\"overflow:auto;max-height:75vh\"><img id=\"topdown\" src=\"" << png_data_uri(png_bytes)
    << "\" alt=\"top-down map\" style=\"max-width:100%;image-rendering:pixelated\"></div>";
  char scale[200];
  std::snprintf(
      scale, sizeof scale,
      "<p>Scale: the bar under the map is %s m; one cell is %s m (%d px); x to the right, y up, from (%s, %s) m "
      "to (%s, %s) m.</p>\n",
      significant(scale_bar_m(g.bounds.sizes().x())).c_str(), significant(r.top_down.cell_m).c_str(), g.scale,
      significant(g.bounds.min().x()).c_str(), significant(g.bounds.min().y()).c_str(),
      significant(g.bounds.max().x()).c_str(), significant(g.bounds.max().y()).c_str());
  h << scale;
  return h.str();
}

std::string depth_frames_html(const run::RunResult& r, const std::filesystem::path& out) {
  std::vector<std::filesystem::path> frames;
  std::error_code error;
  if (std::filesystem::is_directory(out / "frames", error))
    for (const auto& f : std::filesystem::directory_iterator(out / "frames"))
      if (f.path().filename().string().find("_color.png") != std::string::npos) frames.push_back(f.path());
  std::sort(frames.begin(), frames.end());
  std::ostringstream h;
  h << "<h2>Sample depth frames</h2>\n";
  const auto& cams = r.scenario.pipeline.cameras;
  if (!cams.empty()) {
    // The colours of sensors::write_depth_png_colorized: turbo from the camera's minimum range to 6 m.
    h << "<p class=\"legend\">Depth <span class=\"turbo\"></span> from "
      << significant(cams.front().intrinsics.min_range_m)
      << " m (dark blue) to 6 m and beyond (dark red); black: no return. Noise as the map received it.</p>\n";
  }
  // Several cameras: a row per camera, its files named <camera>_depth_NNNNN.
  for (const auto& c : cams) {
    const std::string prefix = cams.size() > 1 ? c.name + "_depth_" : "depth_";
    if (cams.size() > 1) h << "<h3>" << xml_escape(c.name) << "</h3>\n";
    for (const auto& f : frames) {
      const std::string name = f.filename().string();
      if (name.rfind(prefix, 0) == 0)
        h << "<img src=\"" << png_file_data_uri(f) << "\" width=\"424\" alt=\"" << xml_escape(name) << "\" title=\""
          << xml_escape(name) << "\"> ";
    }
  }
  return h.str() + "\n";
}

std::string map_contents_html(const run::RunResult& r) {
  const auto& map = r.scenario.pipeline.map;
  const char* model = map.decay_model == mapping::DecayModel::kLinear ? "linear: a voxel leaves"
                      : map.decay_model == mapping::DecayModel::kExponential
                          ? "exponential: a voxel leaves about"
                          : "persistent: voxels never decay and leave";
  std::ostringstream h;
  h << "<p>What the final map holds: STVL forgets. Each voxel carries the time it was last marked and leaves the map "
       "when "
       "it decays (voxel_decay "
    << significant(map.voxel_decay_s) << " s, " << model
    << (map.decay_model == mapping::DecayModel::kPersistent
            ? " only"
            : " " + significant(map.voxel_decay_s) + " s after its last mark, sooner")
    << " when the camera's clearing frustum sweeps it). Surfaces passed long ago have decayed, so the 3D view and "
       "costmap show the last stretch of the drive, not every surface seen; the map quality above is averaged over the "
       "run's evaluations.</p>\n";
  return h.str();
}

std::string significant(double value) {
  if (!std::isfinite(value)) return value != value ? "NaN" : value > 0 ? "inf" : "-inf";
  if (value == std::round(value) && std::fabs(value) < 1e15) return std::to_string(static_cast<long long>(value));
  return general(value, 4);
}

void write_timing_table(std::ostream& h, const nlohmann::json& timing_ms) {
  h << "<h2>Timing</h2><table><tr><th>stage</th><th>mean ms</th><th>p50 ms</th><th>p95 ms</th></tr>\n";
  for (const auto& [stage, stats] : timing_ms.items()) {
    if (stage == "evaluation_phases" || stage == "per_camera" || stage == "soak") continue;
    h << "<tr><td>" << stage << "</td><td>" << stats["mean"].get<double>() << "</td><td>" << stats["p50"].get<double>()
      << "</td><td>" << stats["p95"].get<double>() << "</td></tr>\n";
  }
  h << "</table>\n";
}

namespace {

// Every leaf under `j` as "a.b[2].c" -> value text (numbers to 4 significant digits), in the document's order.
void flatten(const nlohmann::json& j, const std::string& path, std::vector<std::pair<std::string, std::string>>& out) {
  if (j.is_object()) {
    for (const auto& [key, value] : j.items()) flatten(value, path.empty() ? key : path + "." + key, out);
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i) flatten(j[i], path + "[" + std::to_string(i) + "]", out);
    if (j.empty()) out.emplace_back(path, "(none)");
  } else if (j.is_number()) {
    out.emplace_back(path, significant(j.get<double>()));
  } else {
    out.emplace_back(path, j.is_string() ? j.get<std::string>() : j.dump());
  }
}

std::string count(const nlohmann::json& v) { return significant(v.get<double>()); }

// The failure-mode table's rows: one per mode, with the verdict of the checks (in metrics["checks"]) that judge it.
class FailureModeRows {
 public:
  FailureModeRows(const nlohmann::json& metrics, std::ostream& h) : h_(h) {
    if (metrics.contains("checks"))
      for (const auto& c : metrics.at("checks")) checks_[c.at("name").get<std::string>()] = &c;
  }

  void row(const std::string& mode, const std::string& figure, const std::string& meaning,
           std::initializer_list<const char*> judged_by) const {
    std::string verdict, cls = "";
    for (const char* name : judged_by) {
      const auto it = checks_.find(name);
      if (it == checks_.end()) continue;
      const std::string status = it->second->value("status", it->second->value("passed", false) ? "pass" : "fail");
      if (status == "fail") cls = "fail";
      else if (cls.empty() && status == "pass") cls = "pass";
      verdict += std::string(verdict.empty() ? "" : "; ") + name + ": " +
                 (status == "not_evaluated" ? "not evaluated"
                  : status == "pass"        ? "pass"
                                            : "FAIL");
    }
    if (verdict.empty()) verdict = "not checked by this scenario", cls = "skip";
    h_ << "<tr><td>" << xml_escape(mode) << "</td><td>" << xml_escape(figure) << "</td><td>" << xml_escape(meaning)
       << "</td><td class=\"" << cls << "\">" << xml_escape(verdict) << "</td></tr>\n";
  }

 private:
  std::map<std::string, const nlohmann::json*> checks_;
  std::ostream& h_;
};

// The rows every run has, from metrics["evaluation"]: ghosts, a marked floor, clearing rays, costmap ghosts, stale
// voxels.
void map_failure_rows(const FailureModeRows& rows, const nlohmann::json& e) {
  const nlohmann::json& mean = e.at("mean");
  rows.row("ghosts (phantom obstacles)",
           count(e.at("final").at("phantom_obstacles")) + " at the end, at most " +
               count(mean.at("max_phantom_obstacles")) + " at one evaluation",
           "lethal groups with no true obstacle near them: a planner detours around nothing", {"phantom_obstacles"});
  if (mean.contains("max_path_free_lethal"))
    rows.row("lethal where the truth is free, on the path (a floor marked)",
             "at worst " + count(mean.at("max_path_free_lethal")) +
                 " cells within the path's corridor; costmap precision " +
                 (mean.at("costmap_precision").is_null() ? std::string("not evaluated")
                                                         : significant(mean.at("costmap_precision").get<double>())),
             "cells a robot must drive through marked lethal: the path is blocked",
             {"path_free_lethal", "costmap_precision"});
  rows.row("rays clearing true voxels",
           count(e.at("clearing").at("false_clears")) + " true obstacle voxels removed by clearing",
           "ray-cast clearing erasing what is there (rays grazing a surface); 0 with frustum clearing", {});
  rows.row("costmap ghosts",
           "at worst " + count(mean.at("max_lethal_without_voxels")) + " lethal cells without voxels, " +
               count(mean.at("max_columns_without_lethal")) + " voxel columns without a lethal cell",
           "the 2D costmap disagreeing with the voxels it is projected from", {"costmap_ghosts"});
  rows.row("stale voxels of moved bodies",
           count(e.at("clearing").at("stale_voxels_seen_through")) + " seen through, max latency " +
               significant(e.at("clearing").at("max_latency_s").get<double>()) + " s, " +
               count(e.at("clearing").at("not_cleared")) + " never cleared",
           "a body that moved away still blocks its old place until the camera clears it", {"clearing_latency"});
}

// The rows of the modes under evaluation.failure_modes that this run measured: occlusion, self-marking, outages.
void measured_failure_rows(const FailureModeRows& rows, const nlohmann::json& fm) {
  if (fm.contains("occlusion")) {
    const auto& o = fm.at("occlusion");
    std::size_t vanished = 0;
    for (const auto& b : o.value("bodies", nlohmann::json::array()))
      vanished += !b.value("vanished_s", nlohmann::json()).is_null();
    rows.row("occluded obstacles erased (STVL #134)",
             count(o.at("hidden_false_clears")) + " true voxels cleared while hidden; " + std::to_string(vanished) +
                 " bodies vanished from the map",
             "frustum clearing removes what a nearer object hides; a handful of voxels at edges is harmless, a body "
             "that vanishes is an obstacle the planner no longer sees",
             {"hidden_false_clears"});
  }
  if (fm.contains("self_marking"))
    rows.row("the robot marks itself (STVL #214)",
             "at worst " + count(fm.at("self_marking").at("max_self_lethal_cells")) + " lethal cells on the robot",
             "the robot's own body or mast in the costmap: it cannot move", {"self_lethal_cells"});
  if (fm.contains("outage")) {
    std::size_t outages = 0, cleared = 0, watched = 0;
    for (const auto& c : fm.at("outage").at("cameras"))
      for (const auto& o : c.at("outages"))
        ++outages, cleared += o.value("cleared", 0u), watched += o.value("only_seen_voxels", 0u);
    if (outages > 0)
      rows.row("a camera that stops",
               std::to_string(outages) + " outages: " + std::to_string(cleared) + " of " + std::to_string(watched) +
                   " voxels only that camera had seen left the map",
               "what a stopped camera saw is forgotten or kept stale", {"outage_cleared", "outage_resume"});
  }
}

// A folded table of every leaf under evaluation.failure_modes.
void every_failure_figure_html(std::ostream& h, const nlohmann::json& fm) {
  std::vector<std::pair<std::string, std::string>> leaves;
  flatten(fm, "", leaves);
  h << "<details><summary>Every figure under evaluation.failure_modes (" << leaves.size()
    << ")</summary><table><tr><th>figure</th><th>value</th></tr>\n";
  for (const auto& [figure, value] : leaves)
    h << "<tr><td>" << xml_escape(figure) << "</td><td>" << xml_escape(value) << "</td></tr>\n";
  h << "</table></details>\n";
}

}  // namespace

std::string failure_modes_html(const nlohmann::json& metrics) {
  const nlohmann::json& e = metrics.at("evaluation");
  std::ostringstream h;
  h << "<h2>Failure modes</h2><p>STVL's known failure modes as this run measured them against truth: one row each, "
       "with the check that judges it where the scenario sets one (docs/fidelity.md says which scenario reproduces "
       "each and which option fixes it).</p>"
       "<table><tr><th>failure mode</th><th>this run</th><th>what it means</th><th>verdict</th></tr>\n";
  const FailureModeRows rows(metrics, h);
  map_failure_rows(rows, e);
  if (e.contains("failure_modes")) measured_failure_rows(rows, e.at("failure_modes"));
  h << "</table>\n";
  if (e.contains("failure_modes")) every_failure_figure_html(h, e.at("failure_modes"));
  return h.str();
}

// nav2's master costmap (the bench's model; null when not modelled): its settings, ghosts against STVL's layer after
// each update, its lethal cells at the end and those against the final truth (false: no true obstacle within the
// evaluation's tolerance; phantoms as the evaluation's).
nlohmann::json nav2_json(const run::RunResult& r) {
  if (!r.nav2_master) return nullptr;
  const layer::Nav2CostmapConfig& c = r.nav2_config;
  const layer::Nav2Ghosts& g = r.nav2_ghosts;
  std::size_t lethal = 0;
  for (auto cell : r.nav2_master->cells) lethal += cell == mapping::kCostLethal;
  nlohmann::json phantoms = nlohmann::json::array();
  for (const evaluation::Phantom& p : r.nav2_truth.phantoms)
    phantoms.push_back({{"x_m", p.x_m}, {"y_m", p.y_m}, {"cells", p.cells}});
  return {{"width_m", c.width_m},
          {"height_m", c.height_m},
          {"resolution_m", c.resolution_m},
          {"rolling_window", c.rolling_window},
          {"combination_method", r.scenario.pipeline.layer_type == layer::LayerType::kStvl
                                     ? c.combination_method
                                     : r.scenario.pipeline.nav2_layer.combination_method},
          {"track_unknown_space", c.track_unknown_space},
          {"touch_cleared_cells", c.touch_cleared_cells},
          {"updates", g.updates},
          {"updates_with_ghosts", g.updates_with_ghosts},
          {"max_ghost_cells", g.max_cells},
          {"max_ghost_at_s", g.max_at_s},
          {"final_ghost_cells", g.last_cells},
          {"final_lethal_cells", lethal},
          {"final_false_lethal_cells", r.nav2_truth.false_lethal},
          {"final_phantom_obstacles", r.nav2_truth.phantoms.size()},
          {"final_phantoms", phantoms}};
}

nlohmann::json camera_list_json(const config::Scenario& s) {
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t i = 0; i < s.pipeline.cameras.size(); ++i) {
    const auto& c = s.pipeline.cameras[i];
    nlohmann::json sources = nlohmann::json::array();
    for (std::size_t k = 0; k < c.sources.size(); ++k) {
      const auto& p = c.sources[k].params;
      sources.push_back(
          {{"name", c.sources[k].name},
           {"marking", p.marking},
           {"clearing", p.clearing},
           {"topic", run::source_cloud_topic(s.pipeline.cameras, i, k)},
           {"sensor_frame", p.sensor_frame == mapping::SensorFrame::kLink ? recording::camera_link_frame(c.name)
                                                                          : recording::camera_optical_frame(c.name)},
           {"model_type", static_cast<int>(p.model)},
           {"vertical_fov_padding", p.vertical_fov_padding_m},
           {"obstacle_range", p.obstacle_range_m},
           {"min_obstacle_height", p.min_obstacle_height_m},
           {"max_obstacle_height", p.max_obstacle_height_m},
           {"height_band", p.height_band},
           {"z_reference_frame",
            p.z_reference == mapping::ZReference::kBaseLink ? recording::kBaseFrame : recording::kMapFrame},
           {"min_z", p.min_z_m},
           {"max_z", p.max_z_m},
           {"horizontal_fov_angle", p.horizontal_fov_rad},
           {"vertical_fov_angle", p.vertical_fov_rad},
           {"decay_acceleration", p.decay_acceleration_per_s3},
           {"observation_persistence", p.observation_persistence_s},
           {"expected_update_rate", p.expected_update_rate_s},
           // nav2's layers' ranges (map.layer_type nav2_voxel / nav2_obstacle read these, not obstacle_range)
           {"obstacle_max_range", c.sources[k].nav2.obstacle_max_range_m},
           {"obstacle_min_range", c.sources[k].nav2.obstacle_min_range_m},
           {"raytrace_max_range", c.sources[k].nav2.raytrace_max_range_m},
           {"raytrace_min_range", c.sources[k].nav2.raytrace_min_range_m}});
    }
    list.push_back({{"name", c.name},
                    {"width", c.intrinsics.width},
                    {"height", c.intrinsics.height},
                    {"rate_hz", c.intrinsics.rate_hz},
                    {"noise", c.noise.enabled},
                    {"sources", sources}});
  }
  return list;
}

}  // namespace stvl::report

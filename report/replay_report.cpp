// metrics.json and report.html of a replayed recording (tools/replay.hpp).
#include <algorithm>
#include <sstream>

#include "common/atomic_file.hpp"
#include "common/markup.hpp"
#include "common/units.hpp"
#include "report/machine.hpp"
#include "report/raster.hpp"
#include "report/report.hpp"
#include "report/report_page.hpp"
#include "report/report_sections.hpp"
#include "run/replay.hpp"

namespace stvl::report {
namespace {

// The costmap for people: lethal black, free white, unknown light grey; the base's path in blue. Top row = highest y.
RgbImage costmap_image(const mapping::Costmap2D& c, const std::vector<Eigen::Vector2d>& path_W) {
  const int scale = std::max(1, std::min(8, 1200 / std::max(1, std::max(c.width, c.height))));
  RgbImage image(std::max(1, c.width * scale), std::max(1, c.height * scale));
  for (int iy = 0; iy < c.height; ++iy)
    for (int ix = 0; ix < c.width; ++ix) {
      const std::uint8_t v = c.at(ix, iy);
      const Rgb color = v == mapping::kCostLethal    ? Rgb{0, 0, 0}
                        : v == mapping::kCostUnknown ? Rgb{205, 205, 205}
                                                     : Rgb{255, 255, 255};
      const int y = (c.height - 1 - iy) * scale;
      image.fill_rect(ix * scale, y, ix * scale + scale - 1, y + scale - 1, color);
    }
  const auto px = [&](const Eigen::Vector2d& p) {
    return std::pair<int, int>(int((p.x() - c.origin_m.x()) / c.resolution_m * scale),
                               image.height() - 1 - int((p.y() - c.origin_m.y()) / c.resolution_m * scale));
  };
  for (std::size_t i = 1; i < path_W.size(); ++i) {
    const auto [x0, y0] = px(path_W[i - 1]);
    const auto [x1, y1] = px(path_W[i]);
    image.line(x0, y0, x1, y1, {30, 90, 220});
  }
  if (!path_W.empty()) {
    const auto [x, y] = px(path_W.back());
    image.fill_rect(x - 2, y - 2, x + 2, y + 2, {30, 90, 220});
  }
  return image;
}

// The page's head and the notice that a recording has no ground truth.
void write_replay_head(std::ostream& h, const recording::RecordingInfo& info, const ReportScripts& scripts) {
  h << "<!doctype html><html><head><meta charset=\"utf-8\"><title>stvl-bench replay: " << xml_escape(info.path)
    << "</title><style>body{font-family:sans-serif;margin:2em;max-width:1900px}table{border-collapse:collapse}"
       "td,th{border:1px solid #ccc;padding:3px 8px;text-align:left}img{max-width:100%;border:1px solid #ddd}"
       ".notice{background:#fff4d6;border:1px solid #e0b84a;padding:0.6em 1em}"
    << legend_css() << "</style>\n"
    << interactive_head_html(scripts) << "</head><body>\n";
  h << "<h1>Replay of " << xml_escape(std::filesystem::path(info.path).filename().string()) << "</h1>\n"
    << "<p class=\"notice\"><b>No ground truth.</b> This is a recording, not a simulation: nothing here says whether "
       "a voxel is right. The map, costmap and timings are what the pipeline made of the recorded depth; there are no "
       "precision, recall, phantom or clearing figures and no checks.</p>\n";
}

// "Recording": the file, its topics, intrinsics, depth unit and poses, then what the replay made of it.
void write_recording_table(std::ostream& h, const ReplayResult& r) {
  const auto& info = r.recording;
  const auto& k = r.pipeline.cameras.front().intrinsics;
  h << "<h2>Recording</h2><table>\n";
  const auto row = [&](const std::string& key, const std::string& value) {
    h << "<tr><th>" << xml_escape(key) << "</th><td>" << xml_escape(value) << "</td></tr>\n";
  };
  std::ostringstream intrinsics;
  intrinsics << k.width << " x " << k.height << ", fx " << k.fx << ", fy " << k.fy << ", cx " << k.cx << ", cy " << k.cy
             << " px (" << degrees(k.hfov_rad()) << " x " << degrees(k.vfov_rad()) << " deg)";
  row("file", info.path);
  row("format", info.format);
  if (!info.depth_topic.empty()) row("depth topic", info.depth_topic + " (" + info.encoding + ")");
  if (!info.info_topic.empty()) row("camera info topic", info.info_topic);
  row("intrinsics", intrinsics.str());
  row("depth unit", std::to_string(info.depth_unit_m) + " m");
  row("poses", std::string(recording::to_string(info.pose_source)) + ", fixed frame '" + info.fixed_frame +
                   "', camera frame '" + info.camera_frame + "'");
  row("frames", std::to_string(r.frames) + " replayed of " + std::to_string(info.frame_count) + ", " +
                    std::to_string(r.sim_time_s) + " s recorded, replayed in " + std::to_string(r.wall_time_s) +
                    " s (real-time factor " + std::to_string(r.real_time_factor) + ")");
  row("pipeline", "voxel " + std::to_string(r.pipeline.map.voxel_size_m) + " m, filter " +
                      filter::to_string(r.pipeline.filter.type) + " on " + r.filter_device + ", edge filter " +
                      (r.pipeline.cameras.front().edge_filter.enabled ? "on" : "off") + ", " +
                      std::to_string(r.pipeline.cameras.front().sources.size()) + " observation source(s)");
  row("map", std::to_string(r.final_voxels) + " voxels, " + std::to_string(r.lethal_cells) + " lethal costmap cells");
  std::ostringstream points;
  points << mean_of(r.points_raw) << " raw points per frame, " << mean_of(r.points_filtered)
         << " decimated in the marking band; " << 100.0 * mean_of(r.valid_fraction) << " % of the pixels have depth";
  row("points", points.str());
  h << "</table>\n";
}

// "Topics": every topic of a bag, what the replay read it as, or that it was not read (and why, where known).
void write_topics_table(std::ostream& h, const recording::RecordingInfo& info) {
  if (info.topics.empty()) return;
  h << "<h2>Topics</h2><table>\n<tr><th>topic</th><th>type</th><th>messages</th><th>encoding</th><th>schema</th>"
       "<th>read as</th></tr>\n";
  for (const auto& t : info.topics) {
    h << "<tr><td>" << xml_escape(t.name) << "</td><td>" << xml_escape(t.type) << "</td><td>" << t.messages
      << "</td><td>" << xml_escape(t.message_encoding) << "</td><td>"
      << xml_escape(t.schema_encoding.empty() ? "none" : t.schema_encoding) << "</td><td>"
      << xml_escape(t.use.empty() ? "not read" + (t.note.empty() ? std::string() : ": " + t.note) : t.use)
      << "</td></tr>\n";
  }
  h << "</table>\n";
}

// The interactive map view of every final voxel (no truth to colour them by) and the stage series.
std::string replay_map_html(const ReplayResult& r, const ReportScripts& scripts) {
  std::ostringstream caption;
  caption << "Every voxel of the final map in blue (" << r.map_view.unjudged
          << (r.map_view.unjudged_W.cols() < Eigen::Index(r.map_view.unjudged)
                  ? ", thinned for the browser by a hash of the voxel key"
                  : "")
          << "), the camera's base in black; no truth to colour them by.";
  PageSeries series;
  series.stages = {{"cloud", &r.times.cloud},
                   {"filter", &r.times.filter},
                   {"clear", &r.times.clear},
                   {"mark", &r.times.mark},
                   {"bag", &r.times.bag}};
  series.points_raw = &r.points_raw, series.points_filtered = &r.points_filtered, series.map_voxels = &r.map_voxels;
  series.path_W = &r.path_W, series.view = &r.map_view;
  return interactive_body_html(series, caption.str(), scripts);
}

// The sampled depth frames in out/frames/ inlined, under the depth colour scale.
void write_recorded_frames(std::ostream& h, const ReplayResult& r, const std::filesystem::path& out) {
  h << "<h2>Recorded depth frames</h2>\n";
  for (std::size_t index : r.sampled_frames) {
    char name[64];
    std::snprintf(name, sizeof name, "depth_%05zu_color.png", index);
    h << "<img src=\"" << png_file_data_uri(out / "frames" / name) << "\" width=\"424\" alt=\"" << name << "\"> ";
  }
  h << "<p class=\"legend\">Depth <span class=\"turbo\"></span> from "
    << significant(r.pipeline.cameras.front().intrinsics.min_range_m)
    << " m (dark blue) to 6 m and beyond (dark red); black: no depth.</p>\n";
}

}  // namespace

nlohmann::json replay_metrics_json(const ReplayResult& r) {
  const auto& info = r.recording;
  nlohmann::json topics = nlohmann::json::array();
  for (const auto& t : info.topics)
    topics.push_back({{"name", t.name},
                      {"type", t.type},
                      {"messages", t.messages},
                      {"message_encoding", t.message_encoding},
                      {"schema_encoding", t.schema_encoding},
                      {"use", t.use},
                      {"note", t.note}});
  const auto& k = r.pipeline.cameras.front().intrinsics;
  nlohmann::json sources = nlohmann::json::array();
  for (const auto& s : r.sources) {
    double stale_s = 0;
    for (const auto& span : s.stale) stale_s += span.to_s - span.from_s;
    sources.push_back({{"name", s.source}, {"stale_s", stale_s}, {"reapplied_readings", s.reapplied_readings}});
  }
  nlohmann::json timing = {{"cloud", stage_stats(r.times.cloud)}, {"filter", stage_stats(r.times.filter)},
                           {"clear", stage_stats(r.times.clear)}, {"mark", stage_stats(r.times.mark)},
                           {"bag", stage_stats(r.times.bag)},     {"frame", stage_stats(r.times.frame)}};
  return {{"kind", "replay"},
          {"ground_truth", false},
          {"recording",
           {{"path", info.path},
            {"format", info.format},
            {"depth_topic", info.depth_topic},
            {"info_topic", info.info_topic},
            {"encoding", info.encoding},
            {"depth_unit_m", info.depth_unit_m},
            {"camera_frame", info.camera_frame},
            {"fixed_frame", info.fixed_frame},
            {"pose_source", recording::to_string(info.pose_source)},
            {"frames", info.frame_count},
            {"duration_s", info.end_time_s - info.start_time_s},
            {"width", k.width},
            {"height", k.height},
            {"fx", k.fx},
            {"fy", k.fy},
            {"cx", k.cx},
            {"cy", k.cy},
            {"topics", topics}}},
          {"frames", r.frames},
          {"sampled_frames", r.sampled_frames},
          {"recorded_s", r.sim_time_s},
          {"wall_time_s", r.wall_time_s},
          {"real_time_factor", r.real_time_factor},
          {"machine", machine_json()},
          {"voxel_size_m", r.pipeline.map.voxel_size_m},
          {"filter", filter::to_string(r.pipeline.filter.type)},
          {"filter_device", r.filter_device},
          {"edge_filter", r.pipeline.cameras.front().edge_filter.enabled},
          {"valid_fraction_mean", mean_of(r.valid_fraction)},
          {"points", {{"raw_mean", mean_of(r.points_raw)}, {"marking_mean", mean_of(r.points_filtered)}}},
          {"map", {{"voxels", r.final_voxels}, {"costmap_lethal_cells", r.lethal_cells}}},
          {"sources", sources},
          {"timing_ms", timing}};
}

void write_replay_report(const ReplayResult& r, const std::filesystem::path& out) {
  const nlohmann::json metrics = replay_metrics_json(r);
  write_file_atomically(out / "metrics.json", metrics.dump(2) + "\n");
  const bool costmap = r.final_voxels > 0;
  if (costmap) write_png(out / "costmap.png", costmap_image(r.costmap, r.path_W));
  const ReportScripts scripts = load_report_scripts();
  std::ostringstream h;
  h.precision(4);
  write_replay_head(h, r.recording, scripts);
  write_recording_table(h, r);
  write_topics_table(h, r.recording);
  h << replay_map_html(r, scripts);
  if (costmap) {
    h << "<h2>Costmap</h2><p><img src=\"" << png_file_data_uri(out / "costmap.png")
      << "\" alt=\"costmap\" style=\"image-rendering:pixelated\"></p>"
         "<p>Black: lethal; white: free; grey: unknown; blue: the camera's base over the recording.</p>\n";
  }
  write_recorded_frames(h, r, out);
  write_timing_table(h, metrics["timing_ms"]);
  h << "</body></html>\n";
  write_file_atomically(out / "report.html", h.str());
}

}  // namespace stvl::report

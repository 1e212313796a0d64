#pragma once
// The interactive part of report.html: Chart.js charts (time per frame by stage, stacked; precision, recall and
// F1 over time; points per frame raw and decimated; voxels in the map; in closed loop the drive's speed, turn rate
// and events, drawn in the "Closed loop" section's canvas chart-drive) and a three.js view of the final map
// (voxels within tolerance of the truth green, the others red, the truth faint grey, the robot's path black;
// orbit controls). The libraries come from Debian's libjs-chart.js and libjs-three and are inlined, so the page
// opens offline from a CI artifact. The page checks itself once drawn and writes what it found (script errors,
// painted pixels of every chart and of the 3D view) into <pre id="selftest"> for the browser test.
#include <string>

#include "run/runner.hpp"

namespace stvl::report {

using evaluation::MapView;
using run::RunResult;

struct ReportScripts {
  std::string chart_js, three_js, orbit_controls_js;  // empty when the package is not installed
  bool complete() const { return !chart_js.empty() && !three_js.empty() && !orbit_controls_js.empty(); }
};

// Reads the libraries from `root` (Debian installs them under /usr/share/javascript).
ReportScripts load_report_scripts(const std::string& root = "/usr/share/javascript");

// What goes inside <head> (the error capture and the libraries).
std::string interactive_head_html(const ReportScripts& scripts);
// The charts' and the 3D view's sections with their data; a notice naming the missing packages when the
// scripts are incomplete.
std::string interactive_body_html(const RunResult& r, const ReportScripts& scripts);

// The same for a run without ground truth (a replayed recording): the stages present in `stages`, points and
// voxels per frame, and the map's voxels in one colour (view.unjudged_W); no quality chart.
struct PageSeries {
  std::vector<std::pair<std::string, const std::vector<double>*>> stages;  // name, ms per frame
  const std::vector<std::size_t>* points_raw = nullptr;
  const std::vector<std::size_t>* points_filtered = nullptr;
  const std::vector<std::size_t>* map_voxels = nullptr;
  const std::vector<Eigen::Vector2d>* path_W = nullptr;
  const MapView* view = nullptr;
  const evaluation::DriveSummary* drive = nullptr;  // closed loop: the drive's chart (speed, turn rate, events)
  const std::vector<run::TimedFrameEvent>* frame_events = nullptr;        // camera timing: the delays and drops chart
  std::vector<std::string> camera_names;                                  // with frame_events
  const std::vector<sim::LocalizationCorrection>* corrections = nullptr;  // with localization: its corrections
};
std::string interactive_body_html(const PageSeries& series, const std::string& view_caption_html,
                                  const ReportScripts& scripts);

}  // namespace stvl::report

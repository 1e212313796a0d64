#pragma once
// Sections of report.html a person reads at a glance (issue 31): the pictures inlined as data URIs so the page
// is one self-contained file, each with its scale and legend; the failure modes as one readable row each.
#include <nlohmann/json.hpp>

#include <filesystem>
#include <ostream>
#include <string>

#include "report/raster.hpp"
#include "run/runner.hpp"

namespace stvl::report {

// CSS for the legends (.legend .key, .sw swatches, the .turbo depth scale) and <details>.
std::string legend_css();

// RFC 4648 base64 of `bytes`.
std::string base64(const std::string& bytes);
// "data:image/png;base64,..." of PNG bytes.
std::string png_data_uri(const std::string& png_bytes);
// The same of a PNG file's bytes (an empty image's URI when it cannot be read).
std::string png_file_data_uri(const std::filesystem::path& png_file);

// The top-down picture of truth vs map and the robot's path, with a metre scale bar drawn under the map.
RgbImage top_down_image(const run::RunResult& result);
// Its section: the picture inlined, a colour legend and the scale; `zoom` adds the zoom slider.
std::string top_down_html(const run::RunResult& result, const std::string& png_bytes, bool zoom);
// The sample depth frames in out_dir/frames/ inlined, per camera, under a colour scale of depth in metres.
std::string depth_frames_html(const run::RunResult& result, const std::filesystem::path& out_dir);
// What the final map holds: voxels decay (voxel_decay, the model) or are cleared, so it is not every surface seen.
std::string map_contents_html(const run::RunResult& result);

// report.html's "Failure modes" section from a run's metrics: one row per failure mode (this run's figure, what
// it means, the check that judges it and its verdict), then every figure under evaluation.failure_modes folded
// in a <details>, numbers to 4 significant digits. Throws nlohmann::json::exception when a figure every run
// has is missing.
std::string failure_modes_html(const nlohmann::json& metrics);

// A number to 4 significant digits ("22.07", "1284", "0.0003"); integers as they are.
std::string significant(double value);
// "<h2>Timing</h2>" and a table of the mean, p50 and p95 ms of each stage in `timing_ms` (metrics.json's), in the
// precision of `h`; evaluation_phases, per_camera and soak (not stages) are left out.
void write_timing_table(std::ostream& h, const nlohmann::json& timing_ms);
// metrics.json nav2_costmap: the model's settings, its ghosts over the run, its lethal cells at the end (null
// when map.nav2_costmap is off).
nlohmann::json nav2_json(const run::RunResult& r);
// metrics.json cameras: each camera and its sources with the STVL parameters the run used, under STVL's key names
// (angles in radians, lengths in metres), the sensor frame, the band's frame and the topic of its clouds in the
// bag: enough to feed STVL's own code the bag.
nlohmann::json camera_list_json(const config::Scenario& s);
// metrics.json navigation (navigation_json.cpp; a run with navigation.mode closed_loop, r.drive set): the goal, the
// drive's figures against the truth, the tree's events and every planning cycle's attribution.
nlohmann::json navigation_json(const run::RunResult& r);
// report.html "Closed loop" (navigation_html.cpp): the drive's figures, a speed and event timeline, the events and
// the planning cycles blocked by phantoms or driving into the unseen; "" without a closed loop.
std::string navigation_html(const run::RunResult& r);

}  // namespace stvl::report

#include "report/report.hpp"
#include "report/report_sections.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/atomic_file.hpp"
#include "report/raster.hpp"
#include "tests/support/command.hpp"

namespace stvl::report {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t count = 0;
  for (auto pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1)) ++count;
  return count;
}

RunResult synthetic_result() {
  RunResult r;
  r.scenario.name = "corridor <&> \"quoted\"";
  r.scenario.file = "scenarios/x.yaml";
  r.scenario.pipeline.seed = 5;
  r.checks = {{"f1_3d", true, "mean 3D F1 0.9, required >= 0.85"},
              {"phantom<obstacles>", false, "3 phantoms & \"ghosts\" <here>"},
              {"iou_3d", false, "mean 3D IoU 0.2, required >= 0.5"}};
  r.frames = 5;
  r.sim_time_s = 0.4;
  r.wall_time_s = 2.0;
  r.real_time_factor = 0.2;
  r.gl_backend = "osmesa";
  r.filter_device = "cpu";
  r.times.render = {5, 1, 4, 2, 3};
  for (int i = 100; i >= 0; --i) r.times.frame.push_back(i);  // 0..100, descending
  std::rotate(r.times.frame.begin(), r.times.frame.begin() + 37, r.times.frame.end());
  r.evaluation.mean.f1 = 0.75;
  r.evaluation.mean.snapshots = 2;
  r.evaluation.final.phantom_obstacles = 3;
  r.evaluation.final.phantoms = {{1.5, -2.25, 4}, {3.0, 0.5, 2}, {7.25, 1.0, 9}};
  evaluation::EvaluationSnapshot snapshot;
  snapshot.time_s = 1.0;
  snapshot.precision = 0.5;
  r.evaluation.snapshots = {snapshot, snapshot};
  r.evaluation.obstacles = {{"box_1", 100, 40, 0.8, true, true}};
  r.evaluation.accuracy.p90_m = 0.02;
  r.evaluation.clearing.max_latency_s = 0.7;
  r.points_raw = {100, 300};
  r.points_filtered = {10, 30};
  r.map_voxels = {7, 9};
  return r;
}

TEST(ReportProfile, StagesWithTheirShareOfTheFrameAndEvaluationPhasesPerFrame) {
  RunResult r = synthetic_result();
  r.times.frame = {10, 10, 10, 10};
  r.times.render = {4, 4, 4, 4};  // 40 % of the frame
  r.evaluation_phases.frames = 4;
  r.evaluation_phases.evaluations = 2;
  r.evaluation_phases.observe_ms = 6.0;  // 1.5 ms per frame
  const std::string table = profile_table(r);
  EXPECT_THAT(table, HasSubstr("  render            4.00     4.00    40.0 %"));
  EXPECT_THAT(table, HasSubstr("  frame            10.00    10.00   100.0 %"));
  EXPECT_THAT(table, HasSubstr("(2 evaluations;"));
  EXPECT_THAT(table, HasSubstr("  observe           1.50"));
  const auto phases = metrics_json(r)["timing_ms"]["evaluation_phases"];
  EXPECT_DOUBLE_EQ(phases["observe"]["total"].get<double>(), 6.0);
  EXPECT_DOUBLE_EQ(phases["observe"]["per_frame"].get<double>(), 1.5);
}

TEST(ReportJunit, OneTestcasePerCheckAndAFailureForEachFailedOne) {
  const std::string xml = junit_xml(synthetic_result());
  EXPECT_EQ(count_of(xml, "<testcase "), 3u);
  EXPECT_EQ(count_of(xml, "</testcase>"), 3u);
  EXPECT_EQ(count_of(xml, "<failure "), 2u);
  EXPECT_THAT(xml, HasSubstr("<testsuites tests=\"3\" failures=\"2\" skipped=\"0\">"));
  EXPECT_THAT(xml, HasSubstr("name=\"f1_3d\"><system-out>"));
  EXPECT_THAT(xml, HasSubstr("name=\"iou_3d\"><failure message=\"mean 3D IoU 0.2, required &gt;= 0.5\"/>"));
  EXPECT_EQ(xml.rfind("<?xml version=\"1.0\" encoding=\"UTF-8\"?>", 0), 0u);
}

// Issue 31: a check with nothing to judge is a skipped testcase, not a failure, and does not fail the run.
TEST(ReportJunit, ChecksNotEvaluatedAreSkipped) {
  RunResult r = synthetic_result();
  r.checks = {{"f1_3d", true, "mean 3D F1 0.9, required >= 0.85"},
              evaluation::not_evaluated("path_completed", "not evaluated: cut short")};
  const std::string xml = junit_xml(r);
  EXPECT_THAT(xml, HasSubstr("<testsuites tests=\"2\" failures=\"0\" skipped=\"1\">"));
  EXPECT_THAT(xml, HasSubstr("name=\"path_completed\"><skipped message=\"not evaluated: cut short\"/>"));
  EXPECT_TRUE(r.passed());
  const nlohmann::json m = metrics_json(r);
  EXPECT_EQ(m["checks"][1]["status"], "not_evaluated");
  EXPECT_EQ(m["checks"][0]["status"], "pass");
  EXPECT_EQ(m["passed"], true);
}

// Issue 31: metrics.json said filter.type "none" for STVL's default passthrough.
TEST(ReportMetrics, FilterTypeNamesThePassthroughWithoutDecimation) {
  RunResult r = synthetic_result();
  auto& f = r.scenario.pipeline.filter;
  f.type = filter::FilterType::kNone;
  f.passthrough_enabled = true;
  f.passthrough = {0.0, 2.0};
  nlohmann::json j = metrics_json(r)["filter"];
  EXPECT_EQ(j["type"], "passthrough");
  EXPECT_EQ(j["decimation"], "none");
  EXPECT_EQ(j["passthrough_band_m"], nlohmann::json({0.0, 2.0}));
  f.passthrough_enabled = false;
  EXPECT_EQ(metrics_json(r)["filter"]["type"], "none");
  f.type = filter::FilterType::kVoxel;
  f.passthrough_enabled = true;
  j = metrics_json(r)["filter"];
  EXPECT_EQ(j["type"], "voxel");
  EXPECT_EQ(j["passthrough"], true);
}

// Issue 31: without a snapshot to average the mean figures are null, not 0.
TEST(ReportMetrics, MeanFiguresWithoutASnapshotAreNull) {
  RunResult r = synthetic_result();
  r.evaluation.mean.snapshots = 0;
  const auto mean = metrics_json(r)["evaluation"]["mean"];
  EXPECT_EQ(mean["evaluated"], false);
  EXPECT_TRUE(mean["f1"].is_null());
  EXPECT_TRUE(mean["costmap_precision"].is_null());
  r.evaluation.mean.snapshots = 3;
  EXPECT_DOUBLE_EQ(metrics_json(r)["evaluation"]["mean"]["f1"].get<double>(), 0.75);
}

TEST(ReportJunit, TextIsEscaped) {
  const std::string xml = junit_xml(synthetic_result());
  EXPECT_THAT(xml, HasSubstr("name=\"phantom&lt;obstacles&gt;\""));
  EXPECT_THAT(xml, HasSubstr("message=\"3 phantoms &amp; &quot;ghosts&quot; &lt;here&gt;\""));
  EXPECT_THAT(xml, HasSubstr("corridor &lt;&amp;&gt; &quot;quoted&quot;"));
  EXPECT_THAT(xml, Not(HasSubstr("<here>")));
  EXPECT_THAT(xml, Not(HasSubstr("<obstacles>")));
  // Every '&' starts an entity, and no attribute value holds a raw '<'.
  EXPECT_FALSE(std::regex_search(xml, std::regex("&(?!(amp|lt|gt|quot|apos);)")));
  EXPECT_FALSE(std::regex_search(xml, std::regex("=\"[^\"]*<")));
}

TEST(ReportJunit, NoChecksGiveAnEmptySuite) {
  RunResult r;
  r.scenario.name = "empty";
  const std::string xml = junit_xml(r);
  EXPECT_THAT(xml, HasSubstr("tests=\"0\" failures=\"0\""));
  EXPECT_EQ(count_of(xml, "<testcase"), 0u);
}

TEST(ReportMetrics, HoldsEveryFigureOfTheRun) {
  const nlohmann::json m = metrics_json(synthetic_result());
  for (const char* key :
       {"scenario", "scenario_file", "seed", "passed", "interrupted", "frames", "sim_time_s", "voxel_size_m", "filter",
        "gl_backend", "noise", "evaluation", "checks", "points", "timing_ms", "wall_time_s", "real_time_factor"})
    EXPECT_TRUE(m.contains(key)) << key;
  EXPECT_EQ(m["scenario"], "corridor <&> \"quoted\"");
  EXPECT_EQ(m["seed"], 5);
  EXPECT_EQ(m["passed"], false);
  EXPECT_EQ(m["frames"], 5);
  EXPECT_DOUBLE_EQ(m["real_time_factor"].get<double>(), 0.2);
  EXPECT_EQ(m["filter"]["device"], "cpu");
  EXPECT_EQ(m["gl_backend"], "osmesa");
  const auto& e = m["evaluation"];
  for (const char* part : {"mean", "final"})
    for (const char* key : {"time_s", "mapped_voxels", "observed_truth_voxels", "precision", "recall", "f1", "iou",
                            "lethal_cells", "costmap_precision", "costmap_recall", "phantom_obstacles"})
      EXPECT_TRUE(e[part].contains(key)) << part << "." << key;
  EXPECT_DOUBLE_EQ(e["mean"]["f1"].get<double>(), 0.75);
  EXPECT_EQ(e["final"]["phantom_obstacles"], 3);
  ASSERT_EQ(e["final"]["phantoms"].size(), 3u);
  EXPECT_DOUBLE_EQ(e["final"]["phantoms"][0]["y_m"].get<double>(), -2.25);
  EXPECT_EQ(e["final"]["phantoms"][2]["cells"], 9);
  EXPECT_FALSE(e["mean"].contains("phantoms"));
  EXPECT_EQ(e["snapshots"].size(), 2u);
  ASSERT_EQ(e["obstacles"].size(), 1u);
  EXPECT_EQ(e["obstacles"][0]["name"], "box_1");
  EXPECT_EQ(e["obstacles"][0]["detected"], true);
  for (const char* key : {"count", "mean", "median", "p90", "p99", "max"})
    EXPECT_TRUE(e["accuracy_m"].contains(key)) << key;
  EXPECT_DOUBLE_EQ(e["accuracy_m"]["p90"].get<double>(), 0.02);
  for (const char* key : {"stale_voxels_seen_through", "not_cleared", "max_latency_s", "mean_latency_s"})
    EXPECT_TRUE(e["clearing"].contains(key)) << key;
  EXPECT_DOUBLE_EQ(e["clearing"]["max_latency_s"].get<double>(), 0.7);
  ASSERT_EQ(m["checks"].size(), 3u);
  EXPECT_EQ(m["checks"][1]["name"], "phantom<obstacles>");
  EXPECT_EQ(m["checks"][1]["passed"], false);
  EXPECT_DOUBLE_EQ(m["points"]["raw_mean"].get<double>(), 200.0);
  EXPECT_DOUBLE_EQ(m["points"]["filtered_mean"].get<double>(), 20.0);
  EXPECT_EQ(m["points"]["map_voxels_final"], 9);
}

// Issue 31: the section was a dump of ~100 metric paths ("22.066666666666666"); now one row per mode with what it
// means and the verdict of the check that judges it, every figure folded and rounded below.
TEST(ReportFailureModes, OneReadableRowPerModeWithItsVerdictAndEveryFigureFolded) {
  nlohmann::json m = metrics_json(synthetic_result());
  std::string html = failure_modes_html(m);
  EXPECT_THAT(html, HasSubstr("<tr><th>failure mode</th><th>this run</th><th>what it means</th><th>verdict</th></tr>"));
  EXPECT_THAT(html, HasSubstr("<td>ghosts (phantom obstacles)</td><td>3 at the end, at most 0 at one evaluation</td>"));
  EXPECT_THAT(html, HasSubstr("<td class=\"skip\">not checked by this scenario</td>"));
  m["checks"] = {{{"name", "phantom_obstacles"}, {"passed", false}, {"status", "fail"}},
                 {{"name", "hidden_false_clears"}, {"passed", false}, {"status", "not_evaluated"}}};
  m["evaluation"]["failure_modes"]["occlusion"]["hidden_false_clears"] = 1284;
  m["evaluation"]["failure_modes"]["extra"] = {{"ratio", 22.066666666666666}, {"list", nlohmann::json::array()}};
  html = failure_modes_html(m);
  EXPECT_THAT(html, HasSubstr("<td class=\"fail\">phantom_obstacles: FAIL</td>"));
  EXPECT_THAT(html, HasSubstr("1284 true voxels cleared while hidden; 0 bodies vanished from the map"));
  EXPECT_THAT(html, HasSubstr("hidden_false_clears: not evaluated"));
  EXPECT_THAT(html, HasSubstr("<details><summary>Every figure under evaluation.failure_modes ("));
  EXPECT_THAT(html, HasSubstr("<td>extra.ratio</td><td>22.07</td>"));
  EXPECT_THAT(html, HasSubstr("<td>extra.list</td><td>(none)</td>"));
  EXPECT_THAT(html, Not(HasSubstr("22.0666")));
  m["evaluation"].erase("clearing");
  EXPECT_THROW(failure_modes_html(m), nlohmann::json::exception);  // a figure every run has is missing
}

TEST(ReportSections, SignificantDigitsAndBase64) {
  EXPECT_EQ(significant(22.066666666666666), "22.07");
  EXPECT_EQ(significant(1284), "1284");
  EXPECT_EQ(significant(0.000312345), "0.0003123");
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
}

TEST(ReportMetrics, TimingStatsPerStage) {
  const nlohmann::json t = metrics_json(synthetic_result())["timing_ms"];
  for (const char* stage : {"render", "noise", "cloud", "filter", "clear", "mark", "evaluation", "bag", "frame"})
    for (const char* stat : {"mean", "p50", "p95"}) EXPECT_TRUE(t[stage].contains(stat)) << stage << "." << stat;
  EXPECT_DOUBLE_EQ(t["render"]["mean"].get<double>(), 3.0);
  EXPECT_DOUBLE_EQ(t["render"]["p50"].get<double>(), 3.0);
  EXPECT_DOUBLE_EQ(t["render"]["p95"].get<double>(), 5.0);
  EXPECT_DOUBLE_EQ(t["frame"]["mean"].get<double>(), 50.0);
  EXPECT_DOUBLE_EQ(t["frame"]["p50"].get<double>(), 50.0);
  EXPECT_DOUBLE_EQ(t["frame"]["p95"].get<double>(), 95.0);
  EXPECT_DOUBLE_EQ(t["noise"]["mean"].get<double>(), 0.0);  // no samples
  EXPECT_DOUBLE_EQ(t["noise"]["p95"].get<double>(), 0.0);
}

// Soak (issue #270): voxels and leaves, deterministic, under soak; resident memory and map cost, which measure the
// machine, under timing_ms (which the determinism check and compare-metrics.py ignore). Absent when off.
TEST(ReportMetrics, SoakSamplesKeepTheMachineUnderTimings) {
  RunResult r = synthetic_result();
  EXPECT_FALSE(metrics_json(r).contains("soak"));
  EXPECT_FALSE(metrics_json(r)["timing_ms"].contains("soak"));
  r.soak.sample_every_s = 60;
  r.soak.laps = 2;
  r.soak.first_lap_end_s = 75.5;
  r.soak.first_lap_map_ms = 1.25;
  r.soak.first_lap_map_cpu_ms = 1.0;
  r.soak.samples = {{60, 1000, 40, 210.5, 1.5, 1.25}, {120, 1100, 42, 212.0, 1.75, 1.5}};
  const nlohmann::json m = metrics_json(r);
  EXPECT_EQ(m["soak"]["laps"], 2);
  EXPECT_EQ(m["soak"]["first_lap_end_s"], 75.5);
  EXPECT_EQ(m["soak"]["samples"].size(), 2u);
  EXPECT_EQ(m["soak"]["samples"][1], nlohmann::json({{"t_s", 120.0}, {"voxels", 1100}, {"leaves", 42}}));
  EXPECT_EQ(m["timing_ms"]["soak"]["first_lap_map_ms"], 1.25);
  EXPECT_EQ(m["timing_ms"]["soak"]["first_lap_map_cpu_ms"], 1.0);
  EXPECT_EQ(m["timing_ms"]["soak"]["samples"][0],
            nlohmann::json({{"t_s", 60.0}, {"rss_mb", 210.5}, {"map_ms", 1.5}, {"map_cpu_ms", 1.25}}));
  const std::string flat = m["soak"].dump();
  EXPECT_EQ(flat.find("rss"), std::string::npos);
  EXPECT_EQ(flat.find("ms"), std::string::npos);
}

TEST(ReportPassed, AllChecksMustPassAndTheRunMustNotBeInterrupted) {
  RunResult r;
  EXPECT_TRUE(r.passed());  // no checks configured: nothing failed
  r.checks = {{"a", true, ""}, {"b", true, ""}};
  EXPECT_TRUE(r.passed());
  r.checks.push_back({"c", false, ""});
  EXPECT_FALSE(r.passed());
  r.checks.pop_back();
  r.interrupted = true;
  EXPECT_FALSE(r.passed());
  EXPECT_EQ(metrics_json(r)["passed"], false);
}

std::vector<std::uint8_t> decode_png(const std::string& bytes, int& width, int& height) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&image, bytes.data(), bytes.size())) return {};
  image.format = PNG_FORMAT_RGB;
  std::vector<std::uint8_t> rgb(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, rgb.data(), 0, nullptr)) return {};
  width = static_cast<int>(image.width);
  height = static_cast<int>(image.height);
  return rgb;
}

std::uint32_t big_endian(const std::string& bytes, std::size_t at) {
  std::uint32_t value = 0;
  for (std::size_t i = 0; i < 4; ++i) value = value << 8 | static_cast<unsigned char>(bytes[at + i]);
  return value;
}

TEST(Raster, EncodePngWritesAValidImageOfTheRightSize) {
  RgbImage image(7, 5, {10, 20, 30});
  image.set(6, 4, {255, 0, 0});
  const std::string png = encode_png(image);
  ASSERT_GT(png.size(), 33u);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(png.substr(12, 4), "IHDR");
  EXPECT_EQ(big_endian(png, 16), 7u);
  EXPECT_EQ(big_endian(png, 20), 5u);
  int width = 0, height = 0;
  const auto rgb = decode_png(png, width, height);
  ASSERT_EQ(rgb.size(), 7u * 5u * 3u);
  EXPECT_EQ(width, 7);
  EXPECT_EQ(height, 5);
  EXPECT_EQ(std::vector<std::uint8_t>(rgb.begin(), rgb.begin() + 3), (std::vector<std::uint8_t>{10, 20, 30}));
  EXPECT_EQ(std::vector<std::uint8_t>(rgb.end() - 3, rgb.end()), (std::vector<std::uint8_t>{255, 0, 0}));
}

TEST(Raster, BadSizesAreRejected) {
  EXPECT_THROW(RgbImage(0, 5), std::invalid_argument);
  EXPECT_THROW(RgbImage(5, -1), std::invalid_argument);
  EXPECT_THROW(RgbImage(20000, 5), std::invalid_argument);
}

TEST(Raster, DrawingOutsideTheImageIsClipped) {
  const Rgb white{255, 255, 255}, red{255, 0, 0};
  RgbImage image(10, 8);
  image.set(-1, 0, red);
  image.set(10, 0, red);
  image.set(0, 8, red);
  image.fill_rect(20, 20, 30, 30, red);
  image.fill_rect(-30, -30, -20, -20, red);
  image.line(-50, -5, -10, -40, red);
  image.line(INT_MIN / 4, -3, INT_MAX / 4, -3, red);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 10; ++x) ASSERT_EQ(image.at(x, y), white) << x << "," << y;

  image.fill_rect(INT_MIN, INT_MIN, INT_MAX, INT_MAX, red);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 10; ++x) ASSERT_EQ(image.at(x, y), red) << x << "," << y;
}

TEST(Raster, PartlyOutsideShapesDrawTheirInsidePart) {
  const Rgb white{255, 255, 255}, blue{0, 0, 255};
  RgbImage image(10, 8);
  image.fill_rect(12, 6, 7, 20, blue);  // corners in either order
  EXPECT_EQ(image.at(7, 6), blue);
  EXPECT_EQ(image.at(9, 7), blue);
  EXPECT_EQ(image.at(6, 6), white);
  EXPECT_EQ(image.at(7, 5), white);

  RgbImage diagonal(10, 10);
  diagonal.line(-20, -20, 30, 30, blue);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(diagonal.at(i, i), blue) << i;
  EXPECT_EQ(diagonal.at(1, 0), white);
}

// Fails with tools/raster.cpp as it is: line() stops after 4 * (width + height) steps, so a segment that
// starts far outside the image never reaches it. See the clipping patch in the test report.
TEST(Raster, LongLinesStartingFarOutsideStillCrossTheImage) {
  const Rgb blue{0, 0, 255};
  RgbImage image(10, 8);
  image.line(-1000, 3, 1000, 3, blue);
  for (int x = 0; x < 10; ++x) EXPECT_EQ(image.at(x, 3), blue) << x;
}

TEST(ReportFiles, WriteReportWritesEveryOutput) {
  const test::TempDir dir("report_files");
  write_report(synthetic_result(), dir.path());
  for (const char* name : {"metrics.json", "junit.xml", "report.html", "top_down.png"})
    EXPECT_TRUE(fs::is_regular_file(dir.path() / name)) << name;
  EXPECT_EQ(nlohmann::json::parse(test::TempDir::read(dir.path() / "metrics.json"))["frames"], 5);
  EXPECT_THAT(test::TempDir::read(dir.path() / "report.html"), HasSubstr("<h2>Failure modes</h2>"));
}

// Issue 31: report.html loaded top_down.png and frames/ from beside it; a CI keeping only the page showed broken
// images. Now every picture is a data URI, with its legend and scale.
TEST(ReportFiles, TheReportIsOneSelfContainedFile) {
  const test::TempDir dir("report_self_contained");
  RunResult r = synthetic_result();
  r.scenario.pipeline.cameras.resize(1);
  r.top_down.cell_m = 0.05;
  r.top_down.bounds_W = Eigen::AlignedBox2d(Eigen::Vector2d(0, -1), Eigen::Vector2d(10, 1));
  r.top_down.false_positive = {{10, 0}};
  fs::create_directories(dir.path() / "frames");
  write_png(dir.path() / "frames" / "depth_00010_color.png", RgbImage(4, 3));
  write_report(r, dir.path());
  const std::string html = test::TempDir::read(dir.path() / "report.html");
  EXPECT_THAT(html, Not(HasSubstr("src=\"top_down.png\"")));
  EXPECT_THAT(html, Not(HasSubstr("src=\"frames/")));
  EXPECT_EQ(count_of(html, "<img "), count_of(html, "<img id=\"topdown\" src=\"data:image/png;base64,") +
                                         count_of(html, "<img src=\"data:image/png;base64,"));
  EXPECT_EQ(count_of(html, "<img "), 2u);
  EXPECT_THAT(html, HasSubstr("lethal where the truth is free"));
  EXPECT_THAT(html, HasSubstr("Scale: the bar under the map is 2 m"));
  EXPECT_THAT(html, HasSubstr("<span class=\"turbo\"></span>"));
  EXPECT_THAT(html, HasSubstr("STVL forgets"));
  for (const auto& name : dir.names()) EXPECT_EQ(name.find(".tmp"), std::string::npos) << name;
}

TEST(ReportFiles, TruthNotesAreInMetricsAndTheReport) {
  const test::TempDir dir("report_truth");
  RunResult r = synthetic_result();
  r.evaluation.truth = {3, 1, 364, {}};
  nlohmann::json t = metrics_json(r)["evaluation"]["truth"];
  EXPECT_EQ(t["exact"], true);
  EXPECT_EQ(t["mesh_triangles"], 364);
  EXPECT_TRUE(t["notes"].empty());
  r.evaluation.truth.notes = {
      {4, "geom 'scan' (mesh 'scan', body 'room')", "geom 'scan' (mesh 'scan', body 'room') is not closed <here>"}};
  t = metrics_json(r)["evaluation"]["truth"];
  EXPECT_EQ(t["exact"], false);
  EXPECT_EQ(t["notes"][0]["geom"], "geom 'scan' (mesh 'scan', body 'room')");
  write_report(r, dir.path());
  const std::string html = test::TempDir::read(dir.path() / "report.html");
  EXPECT_THAT(
      html, HasSubstr("Truth: 3 obstacle geoms, 1 of them triangle meshes (364 triangles), voxelized exactly except:"));
  EXPECT_THAT(html, HasSubstr("<li>geom 'scan' (mesh 'scan', body 'room') is not closed &lt;here&gt;</li>"));
}

TEST(ReportFiles, SoakSamplesGetATableInTheReport) {
  const test::TempDir dir("report_soak");
  RunResult r = synthetic_result();
  r.soak.sample_every_s = 60;
  r.soak.samples = {{60, 1000, 40, 210.5, 1.5, 1.25}};
  write_report(r, dir.path());
  const std::string html = test::TempDir::read(dir.path() / "report.html");
  EXPECT_THAT(html, HasSubstr("<h2>Soak</h2><p>0 laps; first lap ended at - (not completed)"));
  EXPECT_THAT(html,
              HasSubstr("<tr><td>60</td><td>1000</td><td>40</td><td>210.5</td><td>1.500</td><td>1.250</td></tr>"));
}

}  // namespace
}  // namespace stvl::report

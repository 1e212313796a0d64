#include "report/report_page.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include <nlohmann/json.hpp>

#include "tests/support/command.hpp"

namespace stvl::report {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

ReportScripts fake_scripts() { return {"/*chart*/ var a = '</script>';", "/*three*/", "/*orbit*/"}; }

RunResult small_run() {
  RunResult r;
  r.scenario.evaluation.tolerance_voxels = 1;
  r.times.render = {1.23456, 2.0};
  r.times.mark = {0.5, 0.25};
  r.points_raw = {1000, 1200};
  r.points_filtered = {10, 12};
  r.map_voxels = {3, 4};
  r.path_W = {{0, 0}, {0.5, 0.0}};
  evaluation::EvaluationSnapshot s;
  s.time_s = 1.0, s.f1 = 0.5, s.precision = 0.6, s.recall = 0.4;
  r.evaluation.snapshots = {s};
  r.map_view.voxel_size_m = 0.05;
  r.map_view.mapped_true_W = Eigen::Matrix3Xf::Constant(3, 2, 0.0251f);
  r.map_view.mapped_false_W = Eigen::Matrix3Xf::Constant(3, 1, 1.0f);
  r.map_view.truth_W = Eigen::Matrix3Xf::Constant(3, 3, 0.5f);
  r.map_view.mapped_true = 2, r.map_view.mapped_false = 1, r.map_view.truth = 3;
  return r;
}

nlohmann::json data_of(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"report-data\">";
  const std::size_t begin = html.find(open) + open.size();
  return nlohmann::json::parse(html.substr(begin, html.find("</script>", begin) - begin));
}

TEST(ReportPage, ChartsAnd3DViewWithTheRunsData) {
  const std::string body = interactive_body_html(small_run(), fake_scripts());
  for (const char* id : {"chart-stages", "chart-quality", "chart-points", "chart-voxels"})
    EXPECT_THAT(body, HasSubstr(std::string("<canvas class=\"chart\" id=\"") + id + "\">")) << id;
  EXPECT_THAT(body, HasSubstr("<canvas id=\"view3d\">"));
  EXPECT_THAT(body, HasSubstr("green (2)"));
  EXPECT_THAT(body, Not(HasSubstr("Thinned")));
  const nlohmann::json d = data_of(body);
  EXPECT_DOUBLE_EQ(d["stages"]["render"][0].get<double>(), 1.235);  // rounded to microseconds
  EXPECT_EQ(d["stages"]["mark"].size(), 2u);
  EXPECT_EQ(d["points_raw"], nlohmann::json({1000, 1200}));
  EXPECT_DOUBLE_EQ(d["quality"]["recall"][0].get<double>(), 0.4);
  EXPECT_EQ(d["view"]["tp"].size(), 6u);
  EXPECT_DOUBLE_EQ(d["view"]["tp"][0].get<double>(), 0.025);  // millimetres
  EXPECT_EQ(d["view"]["truth"].size(), 9u);
  EXPECT_EQ(d["view"]["path"], nlohmann::json({0.0, 0.0, 0.5, 0.0}));
  RunResult thinned = small_run();
  thinned.map_view.truth = 30;
  EXPECT_THAT(interactive_body_html(thinned, fake_scripts()), HasSubstr("Thinned for the browser"));
}

TEST(ReportPage, LibrariesAreInlinedSafely) {
  const std::string head = interactive_head_html(fake_scripts());
  EXPECT_THAT(head, HasSubstr("/*chart*/"));
  EXPECT_THAT(head, HasSubstr("/*orbit*/"));
  EXPECT_THAT(head, HasSubstr("var a = '<\\/script>';"));  // a library's "</script" cannot end its element
  EXPECT_THAT(head, HasSubstr("window.__errors"));
}

TEST(ReportPage, MissingLibrariesGiveANoticeAndNoScripts) {
  ReportScripts partial = fake_scripts();
  partial.three_js.clear();
  EXPECT_EQ(interactive_head_html(partial), "");
  const std::string body = interactive_body_html(small_run(), partial);
  EXPECT_THAT(body, HasSubstr("libjs-chart.js and libjs-three"));
  EXPECT_THAT(body, Not(HasSubstr("<canvas")));
  const stvl::test::TempDir dir("report_scripts");
  EXPECT_FALSE(load_report_scripts(dir.path().string()).complete());
  std::filesystem::create_directories(dir.path() / "chart.js");
  std::filesystem::create_directories(dir.path() / "three/examples/js/controls");
  std::ofstream(dir.path() / "chart.js/chart.min.js") << "C";
  std::ofstream(dir.path() / "three/three.min.js") << "T";
  std::ofstream(dir.path() / "three/examples/js/controls/OrbitControls.js") << "O";
  const ReportScripts s = load_report_scripts(dir.path().string());
  EXPECT_TRUE(s.complete());
  EXPECT_EQ(s.chart_js + s.three_js + s.orbit_controls_js, "CTO");
}

}  // namespace
}  // namespace stvl::report

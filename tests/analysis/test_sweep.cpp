#include "analysis/sweep.hpp"
#include "analysis/sweep_page.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "tests/support/command.hpp"
#include "tests/support/invalid_argument.hpp"

namespace stvl::analysis {
namespace {

namespace fs = std::filesystem;
using test::invalid_argument_of;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;

std::size_t lines_of(const std::string& text) {
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

TEST(SweepAxis, ValuesSplitOnTopLevelCommasOnly) {
  const SweepAxis a = parse_sweep_axis("map.voxel_size=0.02, 0.05,0.1");
  EXPECT_EQ(a.key, "map.voxel_size");
  EXPECT_THAT(a.values, ElementsAre("0.02", "0.05", "0.1"));
  EXPECT_FALSE(a.run_option());
  EXPECT_THAT(parse_sweep_axis("robot.start=[0, 0, 0],[1, 0, {a: 1, b: 2}]").values,
              ElementsAre("[0, 0, 0]", "[1, 0, {a: 1, b: 2}]"));
  const SweepAxis o = parse_sweep_axis("voxel-size=0.05,0.1", true);
  EXPECT_EQ(o.key, "--voxel-size");
  EXPECT_TRUE(o.run_option());
}

TEST(SweepAxis, MalformedAxesNameTheArgument) {
  EXPECT_EQ(invalid_argument_of([] { parse_sweep_axis("map.voxel_size"); }),
            "--set map.voxel_size: expected KEY=V1,V2,...");
  EXPECT_EQ(invalid_argument_of([] { parse_sweep_axis("=1,2"); }), "--set =1,2: empty key");
  EXPECT_EQ(invalid_argument_of([] { parse_sweep_axis("a=1,,2"); }), "--set a=1,,2: empty value in the list");
  EXPECT_EQ(invalid_argument_of([] { parse_sweep_axis("a="); }), "--set a=: empty value in the list");
  EXPECT_EQ(invalid_argument_of([] { parse_sweep_axis("voxel-sise=1", true); }),
            "--option voxel-sise=1: unknown run option 'voxel-sise'; did you mean 'voxel-size'?");
}

TEST(SweepSeeds, RangesListsAndMixes) {
  EXPECT_THAT(parse_seeds("1..5"), ElementsAre(1, 2, 3, 4, 5));
  EXPECT_THAT(parse_seeds("7"), ElementsAre(7));
  EXPECT_THAT(parse_seeds("1..3, 9"), ElementsAre(1, 2, 3, 9));
  for (const char* bad : {"", "x", "5..1", "1..", "-1", "1.5", "1..100000", "99999999999999999999"})
    EXPECT_THAT(invalid_argument_of([&] { parse_seeds(bad); }), HasSubstr("--seeds " + std::string(bad) + ":")) << bad;
}

TEST(SweepGrid, CartesianFirstAxisSlowestSeedsFastest) {
  const auto points =
      sweep_grid({parse_sweep_axis("filter.type=voxel,csnb"), parse_sweep_axis("voxel-size=0.02,0.1", true)}, {1, 2});
  ASSERT_EQ(points.size(), 8u);
  EXPECT_THAT(points[0].sets, ElementsAre("filter.type=voxel", "--voxel-size=0.02"));
  EXPECT_EQ(*points[0].seed, 1u);
  EXPECT_EQ(*points[1].seed, 2u);
  EXPECT_THAT(points[2].sets, ElementsAre("filter.type=voxel", "--voxel-size=0.1"));
  EXPECT_THAT(points[7].sets, ElementsAre("filter.type=csnb", "--voxel-size=0.1"));
  EXPECT_EQ(points[7].name, "007_filter.type=csnb_voxel-size=0.1_seed=2");
  EXPECT_EQ(points[7].index, 7u);
  // Unsafe characters never reach a folder name.
  EXPECT_EQ(sweep_grid({parse_sweep_axis("robot.start=[0, 1/2],[1]")}, {})[0].name, "000_robot.start=-0--1-2-");
  // An axis of one value is in the sets, not in the name.
  const auto one = sweep_grid({parse_sweep_axis("duration_s=2"), parse_sweep_axis("a=1,2")}, {});
  EXPECT_EQ(one[1].name, "001_a=2");
  EXPECT_THAT(one[1].sets, ElementsAre("duration_s=2", "a=2"));
  EXPECT_EQ(sweep_grid({}, {4}).size(), 1u);
}

TEST(SweepGrid, EmptyAndHugeGridsAreRejected) {
  EXPECT_THAT(invalid_argument_of([] { sweep_grid({}, {}); }), HasSubstr("an empty grid"));
  SweepAxis empty{"a", {}};
  EXPECT_THAT(invalid_argument_of([&] { sweep_grid({empty}, {1}); }), HasSubstr("the axis a has no value"));
  const SweepAxis ten = parse_sweep_axis("a=1,2,3,4,5,6,7,8,9,10");
  EXPECT_THAT(invalid_argument_of([&] {
                sweep_grid({ten, ten, ten}, {1, 2}, 1000);
              }),
              HasSubstr("more than 1000 points"));
  EXPECT_EQ(sweep_grid({ten, ten, ten}, {}, 1000).size(), 1000u);
}

TEST(SweepCommand, PointCommandsCarrySetsOptionsAndSeed) {
  const auto p =
      sweep_grid({parse_sweep_axis("map.voxel_size=0.1,0.2"), parse_sweep_axis("filter=csnb,voxel", true)}, {3})[0];
  EXPECT_THAT(point_command("/b/stvl-bench", "/s.yaml", "/out", p),
              ElementsAre("/b/stvl-bench", "run", "/s.yaml", "--out", "/out/000_map.voxel_size=0.1_filter=csnb_seed=3",
                          "--no-progress", "--set", "map.voxel_size=0.1", "--filter", "csnb", "--seed", "3"));
  EXPECT_EQ(shell_line({"a b", "it's"}), "'a b' 'it'\\''s'");
}

TEST(SweepEmit, EveryEngineGetsOneJobPerPoint) {
  const stvl::test::TempDir dir("sweep_emit");
  const auto points = sweep_grid({parse_sweep_axis("a=1,2,3")}, {1, 2});
  const std::string out = (dir.path() / "g").string();
  EXPECT_EQ(emit_sweep("parallel", "/b", "/s.yaml", out, points).size(), 2u);  // sweep.json, jobs.txt
  const std::string jobs = stvl::test::TempDir::read(dir.path() / "g" / "jobs.txt");
  EXPECT_EQ(lines_of(jobs), 6u);
  EXPECT_THAT(jobs, HasSubstr("'/b' 'run' '/s.yaml' '--out' '" + fs::absolute(out).string() + "/005_a=3_seed=2'"));
  const auto grid = nlohmann::json::parse(stvl::test::TempDir::read(dir.path() / "g" / "sweep.json"));
  EXPECT_EQ(grid["points"].size(), 6u);
  EXPECT_EQ(grid["points"][5]["seed"], 2);
  emit_sweep("ctest", "/b", "/s.yaml", out, points);
  const std::string tests = stvl::test::TempDir::read(dir.path() / "g" / "CTestTestfile.cmake");
  EXPECT_EQ(static_cast<std::size_t>(std::count(tests.begin(), tests.end(), '\n')), 1u + 2u * 6u);
  EXPECT_THAT(tests, HasSubstr("add_test(sweep.000_a=1_seed=1 \"/b\" \"run\" \"/s.yaml\""));
  emit_sweep("slurm", "/b", "/s.yaml", out, points);
  const std::string sbatch = stvl::test::TempDir::read(dir.path() / "g" / "sweep.sbatch");
  EXPECT_THAT(sbatch, HasSubstr("#SBATCH --array=0-5\n"));
  EXPECT_THAT(sbatch, HasSubstr("$((SLURM_ARRAY_TASK_ID + 1))p"));
  EXPECT_THAT(invalid_argument_of([&] { emit_sweep("make", "/b", "/s.yaml", out, points); }), HasSubstr("--emit make"));
}

TEST(SweepEmit, TwinsRunWithTheirPointAndHaveAGridOfTheirOwn) {
  const stvl::test::TempDir dir("sweep_twins");
  const auto points = sweep_grid({parse_sweep_axis("a=1,2")}, {});
  const std::string out = (dir.path() / "g").string(), twin = (dir.path() / "t").string();
  const std::vector<SweepTwin> twins = {{twin, {"map.b=3", "filter.c=4"}}};
  EXPECT_THAT(point_command("/b", "/s.yaml", "/out", points[1], {{"/t", {"map.b=3"}}}),
              ElementsAre("/b", "run", "/s.yaml", "--out", "/out/001_a=2", "--no-progress", "--set", "a=2", "--twin",
                          "/t/001_a=2;map.b=3"));
  emit_sweep("parallel", "/b", "/s.yaml", out, points, twins);
  const std::string jobs = stvl::test::TempDir::read(dir.path() / "g" / "jobs.txt");
  EXPECT_EQ(lines_of(jobs), 2u);  // one process per point and its twin
  EXPECT_THAT(jobs, HasSubstr("'--twin' '" + fs::absolute(twin).string() + "/000_a=1;map.b=3;filter.c=4'"));
  const auto grid = nlohmann::json::parse(stvl::test::TempDir::read(dir.path() / "t" / "sweep.json"));
  ASSERT_EQ(grid["points"].size(), 2u);
  EXPECT_EQ(grid["points"][1]["name"], "001_a=2");
  EXPECT_EQ(grid["points"][1]["sets"], nlohmann::json({"a=2", "map.b=3", "filter.c=4"}));
  const auto own = nlohmann::json::parse(stvl::test::TempDir::read(dir.path() / "g" / "sweep.json"));
  EXPECT_EQ(own["points"][1]["sets"], nlohmann::json({"a=2"}));
}

TEST(SweepCollect, OneRowPerPointWithItsFiguresOrMissing) {
  const stvl::test::TempDir dir("sweep_collect");
  const auto points =
      sweep_grid({parse_sweep_axis("filter.type=voxel,csnb"), parse_sweep_axis("voxel-size=0.05,0.1", true)}, {1});
  emit_sweep("parallel", "/b", "/s.yaml", dir.path().string(), points);
  for (std::size_t i = 0; i < 3; ++i) {  // the last point never ran
    fs::create_directories(dir.path() / points[i].name);
    const nlohmann::json m = {{"passed", i != 1},
                              {"evaluation", {{"mean", {{"f1", 0.5 + 0.1 * i + 1e-12}}}}},
                              {"timing_ms", {{"filter", {{"mean", 2.0 * (i + 1)}}}}},
                              {"checks",
                               {{{"name", "f1_3d"},
                                 {"passed", i != 1},
                                 {"status", i != 1 ? "pass" : "fail"},
                                 {"message", "mean 3D F1 <low>"}},
                                {{"name", "path_completed"}, {"passed", false}, {"status", "not_evaluated"}}}}};
    std::ofstream(dir.path() / points[i].name / "metrics.json") << m.dump();
  }
  const nlohmann::json table = collect_sweep(dir.path().string(), "/nonexistent/chart.min.js");
  EXPECT_EQ(table["axes"], nlohmann::json({"filter.type", "voxel-size"}));
  ASSERT_EQ(table["rows"].size(), 4u);
  EXPECT_EQ(table["rows"][2]["sets"]["filter.type"], "csnb");
  EXPECT_EQ(table["rows"][2]["seed"], "1");
  EXPECT_EQ(table["rows"][2]["sets"]["voxel-size"], "0.05");
  EXPECT_NEAR(table["rows"][2]["figures"]["f1"].get<double>(), 0.7, 1e-9);
  EXPECT_DOUBLE_EQ(table["rows"][2]["figures"]["filter_ms_mean"].get<double>(), 6.0);
  EXPECT_EQ(table["rows"][1]["state"], "failed");
  EXPECT_EQ(table["rows"][3]["state"], "missing");
  const std::string csv = stvl::test::TempDir::read(dir.path() / "sweep.csv");
  EXPECT_EQ(lines_of(csv), 5u);
  EXPECT_THAT(csv, HasSubstr("point,filter.type,voxel-size,seed,state,f1,"));
  EXPECT_THAT(csv, HasSubstr("002_filter.type=csnb_voxel-size=0.05_seed=1,csnb,0.05,1,passed,0.70000000000"));
  EXPECT_THAT(csv, HasSubstr("003_filter.type=csnb_voxel-size=0.1_seed=1,csnb,0.1,1,missing,"));
  const std::string html = stvl::test::TempDir::read(dir.path() / "sweep.html");
  EXPECT_THAT(html, HasSubstr("No charts"));
  // Issue 31: the failing check named, 3-4 significant digits, a link to each point's report, the table scrolls.
  EXPECT_THAT(html, HasSubstr(">failed: f1_3d</td>"));
  EXPECT_THAT(html, HasSubstr("title=\"mean 3D F1 &lt;low&gt;&#10;\""));
  EXPECT_THAT(html, HasSubstr("<td class=\"n\">0.7</td>"));
  EXPECT_THAT(html, Not(HasSubstr("0.70000000000")));
  EXPECT_THAT(html, HasSubstr("<a href=\"002_filter.type=csnb_voxel-size=0.05_seed=1/report.html\">"));
  EXPECT_THAT(html, HasSubstr("<div class=\"wide\"><table>"));
  EXPECT_THAT(html,
              HasSubstr("4 points, <span class=\"passed\">2 passed</span>, <span class=\"failed\">1 failed</span>"));
  const std::string junit = sweep_junit(table);
  EXPECT_THAT(junit, HasSubstr("<testsuites tests=\"4\" failures=\"1\" errors=\"1\">"));
  EXPECT_THAT(junit, HasSubstr("<failure message=\"failed: f1_3d\">f1_3d: mean 3D F1 &lt;low&gt;"));
  EXPECT_THAT(junit, HasSubstr("<error message=\"the point did not run"));
  EXPECT_THAT(invalid_argument_of([&] { collect_sweep((dir.path() / "none").string()); }), HasSubstr("no sweep.json"));
}

TEST(SweepCollect, ChartsInlineChartJsAndAverageOverSeeds) {
  const std::string chart_js = "/usr/share/javascript/chart.js/chart.min.js";
  if (!fs::is_regular_file(chart_js)) GTEST_SKIP() << "libjs-chart.js is not installed";
  const stvl::test::TempDir dir("sweep_charts");
  const auto points = sweep_grid({parse_sweep_axis("voxel-size=0.05,0.1", true)}, {1, 2});
  emit_sweep("parallel", "/b", "/s.yaml", dir.path().string(), points);
  for (std::size_t i = 0; i < points.size(); ++i) {
    fs::create_directories(dir.path() / points[i].name);
    std::ofstream(dir.path() / points[i].name / "metrics.json")
        << nlohmann::json({{"passed", true}, {"evaluation", {{"mean", {{"f1", 0.1 * (i + 1)}}}}}}).dump();
  }
  collect_sweep(dir.path().string(), chart_js);
  const std::string html = stvl::test::TempDir::read(dir.path() / "sweep.html");
  EXPECT_THAT(html, HasSubstr("new Chart(document.getElementById('f1')"));
  // voxel-size 0.05: seeds 1 and 2 have F1 0.1 and 0.2 -> 0.15; 0.1: 0.3 and 0.4 -> 0.35.
  EXPECT_THAT(html, HasSubstr("\"labels\":[\"0.05\",\"0.1\"]"));
  EXPECT_THAT(html, ::testing::ContainsRegex("\"data\":\\[0\\.15[0-9]*,0\\.35[0-9]*\\]"));
  EXPECT_GT(html.size(), 100000u);                              // Chart.js itself is inlined: the page opens offline
  EXPECT_THAT(html, HasSubstr("\"borderColor\":\"#0072B2\""));  // a colour of its own, not Chart.js's pale grey
  EXPECT_THAT(html, HasSubstr("\"maintainAspectRatio\":false"));
}

}  // namespace
}  // namespace stvl::analysis

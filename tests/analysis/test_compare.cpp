#include "analysis/compare.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <stdexcept>
#include <string>

#include "tests/support/command.hpp"
#include "tests/support/invalid_argument.hpp"

namespace stvl::analysis {
namespace {

using test::invalid_argument_of;
using ::testing::HasSubstr;
using ::testing::Not;

// A metrics.json as a run writes it, cut down to the figures the default rules read, two obstacles and a check.
nlohmann::json run_metrics() {
  const auto stage = [](double mean) { return nlohmann::json{{"mean", mean}, {"p50", mean}, {"p95", 2 * mean}}; };
  return {{"scenario", "corridor"},
          {"passed", true},
          {"evaluation",
           {{"mean",
             {{"f1", 0.9},
              {"precision", 0.92},
              {"recall", 0.88},
              {"costmap_precision", 0.8},
              {"max_phantom_obstacles", 0}}},
            {"final", {{"phantom_obstacles", 0}, {"phantoms", nlohmann::json::array()}}},
            {"snapshots", {{{"f1", 0.1}}, {{"f1", 0.2}}}},
            {"clearing", {{"false_clears", 10}}},
            {"obstacles", {{{"name", "box_1"}, {"best_recall", 1.0}}, {{"name", "desk_1"}, {"best_recall", 0.5}}}}}},
          {"checks", {{{"name", "f1_3d"}, {"passed", true}, {"message", "F1 0.9"}}}},
          {"timing_ms", {{"filter", stage(2.0)}, {"clear", stage(1.0)}, {"mark", stage(0.5)}, {"frame", stage(20.0)}}},
          {"real_time_factor", 1.5},
          {"voxel_size_m", 0.05},
          {"machine", {{"cpu", "Test CPU"}, {"fingerprint", "00000000000000aa"}}}};
}

TEST(CompareRules, ParseValueDeltaAndRatioWithEveryOperator) {
  const CompareRule r = parse_compare_rule("delta(evaluation.mean.f1) < -0.01");
  EXPECT_EQ(r.left, CompareRule::Left::kDelta);
  EXPECT_EQ(r.path, "evaluation.mean.f1");
  EXPECT_EQ(r.op, CompareRule::Op::kLess);
  EXPECT_DOUBLE_EQ(r.threshold, -0.01);
  EXPECT_EQ(parse_compare_rule("ratio( timing_ms.frame.mean )>=1.2").left, CompareRule::Left::kRatio);
  EXPECT_EQ(parse_compare_rule("ratio(timing_ms.frame.mean) >= 1.2").op, CompareRule::Op::kGreaterEqual);
  const CompareRule v = parse_compare_rule("evaluation.obstacles[box_1].best_recall <= 5e-1");
  EXPECT_EQ(v.left, CompareRule::Left::kValue);
  EXPECT_EQ(v.path, "evaluation.obstacles[box_1].best_recall");
  EXPECT_EQ(v.op, CompareRule::Op::kLessEqual);
  EXPECT_DOUBLE_EQ(v.threshold, 0.5);
  EXPECT_EQ(parse_compare_rule("x > 3").op, CompareRule::Op::kGreater);
}

TEST(CompareRules, ExpressionsThatDoNotParseQuoteTheRule) {
  for (const char* bad : {"", "f1", "f1 <", "f1 < x", "f1 == 1", "delta(f1 < 1", "sum(f1) > 1", "f1 < 1 2", "< 1"})
    EXPECT_THAT(invalid_argument_of([&] { parse_compare_rule(bad); }),
                HasSubstr(std::string("--fail-on '") + bad + "': expected"))
        << bad;
}

TEST(Compare, TheSameRunTwiceHasNoRegressionAndNoDifference) {
  const Comparison c = compare_metrics(run_metrics(), run_metrics(), default_compare_rules());
  EXPECT_FALSE(c.regressed());
  EXPECT_TRUE(c.only_in_a.empty());
  EXPECT_TRUE(c.only_in_b.empty());
  for (const auto& m : c.metrics) EXPECT_EQ(m.a, m.b) << m.path;
  for (const auto& m : c.metrics) EXPECT_EQ(m.path.find("snapshots"), std::string::npos) << m.path;
  EXPECT_THAT(comparison_markdown(c), HasSubstr("No regression."));
  EXPECT_THAT(comparison_markdown(c), HasSubstr("0 of " + std::to_string(c.metrics.size()) + " figures differ"));
}

TEST(Compare, PlantedRegressionsAreFlaggedEachByItsRule) {
  nlohmann::json b = run_metrics();
  b["evaluation"]["mean"]["f1"] = 0.885;              // -0.015
  b["evaluation"]["final"]["phantom_obstacles"] = 1;  // a new phantom
  b["timing_ms"]["filter"]["p50"] = 2.5;              // x1.25
  b["timing_ms"]["frame"]["p50"] = 23.0;              // x1.15: within 20 %
  b["timing_ms"]["clear"]["mean"] = 1.69;             // x1.69 on the mean alone: medians are judged
  b["evaluation"]["mean"]["recall"] = 0.875;          // -0.005: within 0.01
  b["checks"][0]["passed"] = false;
  b["checks"][0]["message"] = "F1 0.885, required >= 0.89";
  const Comparison c = compare_metrics(run_metrics(), b, default_compare_rules(), "main", "branch");
  std::vector<std::string> what;
  for (const auto& r : c.regressions) what.push_back(r.what);
  EXPECT_THAT(
      what, ::testing::ElementsAre("delta(evaluation.mean.f1) < -0.01", "delta(evaluation.final.phantom_obstacles) > 0",
                                   "ratio(timing_ms.filter.p50) > 1.2", "check f1_3d"));
  EXPECT_EQ(c.regressions[0].detail, "evaluation.mean.f1: 0.9 -> 0.885 (-0.015)");
  EXPECT_EQ(c.regressions[2].detail, "timing_ms.filter.p50: 2 -> 2.5 (x1.25)");
  EXPECT_EQ(c.regressions[3].detail, "F1 0.885, required >= 0.89");
  const std::string md = comparison_markdown(c);
  EXPECT_THAT(md, HasSubstr("**4 regressions**"));
  EXPECT_THAT(md, HasSubstr("| evaluation.mean.f1 | 0.9 | 0.885 | -0.015 |"));
  EXPECT_THAT(comparison_html(c), HasSubstr("4 regressions"));
  // The same differences in the other direction are improvements, not regressions.
  EXPECT_FALSE(compare_metrics(b, run_metrics(), default_compare_rules()).regressed());
}

TEST(Compare, UserRulesNamedListItemsAndZeroRatios) {
  nlohmann::json b = run_metrics();
  b["evaluation"]["obstacles"][1]["best_recall"] = 0.25;
  const auto rule = parse_compare_rule("evaluation.obstacles[desk_1].best_recall < 0.3");
  EXPECT_TRUE(compare_metrics(run_metrics(), b, {rule}).regressed());
  EXPECT_FALSE(compare_metrics(run_metrics(), run_metrics(), {rule}).regressed());
  // A figure that is 0 in A has no ratio: the rule does not fire.
  nlohmann::json a0 = run_metrics(), b0 = run_metrics();
  a0["timing_ms"]["mark"]["mean"] = 0.0;
  b0["timing_ms"]["mark"]["mean"] = 9.0;
  EXPECT_FALSE(compare_metrics(a0, b0, {parse_compare_rule("ratio(timing_ms.mark.mean) > 1.2")}).regressed());
}

TEST(Compare, AMissingMetricIsAnErrorWithTheNearestName) {
  EXPECT_EQ(invalid_argument_of([&] {
              compare_metrics(run_metrics(), run_metrics(), {parse_compare_rule("delta(evaluation.mean.f2) < 0")});
            }),
            "rule 'delta(evaluation.mean.f2) < 0': evaluation.mean.f2 is not a figure of A; did you mean "
            "'evaluation.mean.f1'?");
  nlohmann::json b = run_metrics();
  b["timing_ms"].erase("filter");
  EXPECT_THAT(invalid_argument_of([&] { compare_metrics(run_metrics(), b, default_compare_rules(), "a", "new"); }),
              HasSubstr("timing_ms.filter.p50 is not a figure of new"));
  const Comparison c = compare_metrics(run_metrics(), b, {});
  EXPECT_EQ(c.only_in_a.size(), 3u);  // mean, p50, p95
}

TEST(Compare, LoadMetricsTakesAFolderOrAFileAndRejectsTheRest) {
  const stvl::test::TempDir dir("compare_load");
  std::ofstream(dir.path() / "metrics.json") << run_metrics().dump();
  EXPECT_EQ(load_metrics(dir.path().string())["scenario"], "corridor");
  EXPECT_EQ(load_metrics((dir.path() / "metrics.json").string())["scenario"], "corridor");
  std::filesystem::create_directories(dir.path() / "empty");
  EXPECT_THAT(invalid_argument_of([&] { load_metrics((dir.path() / "empty").string()); }),
              HasSubstr("no metrics.json"));
  std::ofstream(dir.path() / "bad.json") << "{\"evaluation\": ";
  EXPECT_THAT(invalid_argument_of([&] { load_metrics((dir.path() / "bad.json").string()); }),
              HasSubstr("malformed JSON"));
  std::ofstream(dir.path() / "other.json") << "{\"a\": 1}";
  EXPECT_THAT(invalid_argument_of([&] { load_metrics((dir.path() / "other.json").string()); }),
              HasSubstr("not a stvl-bench metrics.json"));
}

TEST(Compare, TwoReplaysWithoutGroundTruth) {
  // A replay's metrics.json (stvl-bench replay) has no evaluation: it loads, and the defaults without ground
  // truth are the timing rules alone, which find a planted slowdown.
  nlohmann::json a = {
      {"kind", "replay"},
      {"ground_truth", false},
      {"map", {{"voxels", 100}}},
      {"timing_ms",
       {{"filter", {{"p50", 2.0}}}, {"clear", {{"p50", 1.0}}}, {"mark", {{"p50", 1.0}}}, {"frame", {{"p50", 10.0}}}}}};
  nlohmann::json b = a;
  b["timing_ms"]["frame"]["p50"] = 13.0;
  a["machine"] = {{"fingerprint", "f"}};
  b["machine"] = {{"fingerprint", "f"}};
  const stvl::test::TempDir dir("compare_replay");
  std::ofstream(dir.path() / "metrics.json") << a.dump();
  EXPECT_TRUE(is_replay(load_metrics(dir.path().string())));
  EXPECT_FALSE(is_replay(run_metrics()));
  const auto rules = default_compare_rules(false);
  EXPECT_EQ(rules.size(), 4u);
  for (const auto& rule : rules) EXPECT_EQ(rule.path.rfind("timing_ms.", 0), 0u) << rule.text;
  EXPECT_FALSE(compare_metrics(a, a, rules).regressed());
  const Comparison c = compare_metrics(a, b, rules);
  ASSERT_EQ(c.regressions.size(), 1u);
  EXPECT_EQ(c.regressions[0].what, "ratio(timing_ms.frame.p50) > 1.2");
  // The defaults with ground truth ask for figures a replay does not have.
  EXPECT_THAT(invalid_argument_of([&] { compare_metrics(a, b, default_compare_rules()); }),
              HasSubstr("evaluation.mean.f1 is not a figure"));
}

// Issue 31: timings of different machines are reported, not judged; differing settings are shown first; the
// long tables fold; JUnit has a testcase per rule.
TEST(Compare, TimingRulesNeedTheSameMachineAndSettingsComeFirst) {
  nlohmann::json b = run_metrics();
  b["timing_ms"]["frame"]["p50"] = 40.0;  // x2
  b["machine"]["fingerprint"] = "00000000000000bb";
  b["voxel_size_m"] = 0.1;
  Comparison c = compare_metrics(run_metrics(), b, default_compare_rules());
  EXPECT_FALSE(c.regressed());
  EXPECT_FALSE(c.same_machine);
  std::size_t not_judged = 0;
  for (const auto& o : c.outcomes) not_judged += o.status == "not judged";
  EXPECT_EQ(not_judged, 4u);
  ASSERT_EQ(c.config_differences.size(), 2u);
  EXPECT_EQ(c.config_differences[0].path, "machine.fingerprint");
  EXPECT_EQ(c.config_differences[1].path, "voxel_size_m");
  const std::string md = comparison_markdown(c);
  EXPECT_LT(md.find("### Configuration differences (2)"), md.find("### Headline figures"));
  EXPECT_THAT(md, HasSubstr("| voxel_size_m | 0.05 | 0.1 |"));
  EXPECT_THAT(md, HasSubstr("Timing rules not judged (4)"));
  EXPECT_THAT(md, HasSubstr("<details><summary>Every figure that differs ("));
  const std::string junit = comparison_junit(c);
  EXPECT_THAT(junit, HasSubstr("tests=\"10\" failures=\"0\" skipped=\"4\""));
  EXPECT_THAT(
      junit,
      HasSubstr("name=\"ratio(timing_ms.frame.p50) &gt; 1.2\"><skipped message=\"measured on different machines"));
  b["machine"]["fingerprint"] = "00000000000000aa";  // the same machine: judged
  c = compare_metrics(run_metrics(), b, default_compare_rules());
  ASSERT_EQ(c.regressions.size(), 1u);
  EXPECT_EQ(c.regressions[0].what, "ratio(timing_ms.frame.p50) > 1.2");
  EXPECT_THAT(comparison_junit(c), HasSubstr("failures=\"1\" skipped=\"0\""));
  EXPECT_THAT(comparison_markdown(compare_metrics(run_metrics(), run_metrics(), {})), HasSubstr("Same configuration."));
}

TEST(CompareCommand, ExitCodesAndOutputs) {
  const auto bin = stvl::test::stvl_bench_binary();
  if (bin.empty()) GTEST_SKIP() << "stvl-bench is not built";
  const stvl::test::TempDir dir("compare_cmd");
  std::filesystem::create_directories(dir.path() / "a");
  std::filesystem::create_directories(dir.path() / "b");
  nlohmann::json b = run_metrics();
  b["evaluation"]["mean"]["f1"] = 0.5;
  std::ofstream(dir.path() / "a" / "metrics.json") << run_metrics().dump();
  std::ofstream(dir.path() / "b" / "metrics.json") << b.dump();
  const std::string a_dir = stvl::test::quoted((dir.path() / "a").string()),
                    b_dir = stvl::test::quoted((dir.path() / "b").string());
  const std::string cmd = stvl::test::quoted(bin.string()) + " compare ";
  EXPECT_EQ(stvl::test::run_shell(cmd + a_dir + " " + a_dir).exit_code, 0);
  const std::string md = (dir.path() / "out.md").string(), html = (dir.path() / "out.html").string();
  const std::string junit = (dir.path() / "out.xml").string();
  const auto regressed =
      stvl::test::run_shell(cmd + a_dir + " " + b_dir + " --markdown " + stvl::test::quoted(md) + " --html " +
                            stvl::test::quoted(html) + " --junit " + stvl::test::quoted(junit));
  EXPECT_EQ(regressed.exit_code, 1) << regressed.output;
  EXPECT_THAT(stvl::test::TempDir::read(junit), HasSubstr("name=\"delta(evaluation.mean.f1) &lt; -0.01\"><failure "));
  EXPECT_THAT(stvl::test::TempDir::read(md), HasSubstr("delta(evaluation.mean.f1) < -0.01"));
  EXPECT_THAT(stvl::test::TempDir::read(html), HasSubstr("<h2 class=\"bad\">1 regression</h2>"));
  // Only the user's rule: the F1 drop passes, the user's own threshold on it does not.
  EXPECT_EQ(stvl::test::run_shell(cmd + a_dir + " " + b_dir + " --no-default-rules").exit_code, 0);
  EXPECT_EQ(
      stvl::test::run_shell(cmd + a_dir + " " + b_dir + " --no-default-rules --fail-on 'evaluation.mean.f1 < 0.6'")
          .exit_code,
      1);
  const auto bad_rule = stvl::test::run_shell(cmd + a_dir + " " + b_dir + " --fail-on 'f1 = 1'");
  EXPECT_EQ(bad_rule.exit_code, 2);
  EXPECT_THAT(bad_rule.output, HasSubstr("--fail-on 'f1 = 1': expected"));
  const auto missing = stvl::test::run_shell(cmd + a_dir + " " + stvl::test::quoted(dir.path().string()));
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.output, HasSubstr("no metrics.json"));
}

}  // namespace
}  // namespace stvl::analysis

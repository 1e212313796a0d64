#include "evaluation/checks.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace stvl::evaluation {
namespace {

using ::testing::HasSubstr;

evaluation::EvaluationSummary summary() {
  evaluation::EvaluationSummary s;
  s.mean.snapshots = 20;
  s.mean.f1 = 0.9871;
  s.mean.iou = 0.5;
  s.final.phantom_obstacles = 2;
  s.obstacles = {{"box", 10, 8, 0.9, true, true}, {"door", 10, 6, 0.2, true, false}, {"far", 10, 0, 0, false, false}};
  s.clearing.stale_voxels_seen_through = 5;
  s.clearing.max_latency_s = 0.25;
  s.accuracy.p90_m = 0.031;
  s.accuracy.count = 100;
  return s;
}

TEST(Checks, CostmapGhostsAndCameraRecallFailOnTheirWorstValue) {
  ChecksConfig c;
  c.camera_recall_min = 0.8;
  c.costmap_ghosts_max = 0;
  evaluation::EvaluationSummary s = summary();
  s.mean.camera_recall = {0.99, 0.79, 0.95};
  s.mean.max_columns_without_lethal = 1;
  auto r = evaluation_checks(c, s, {"front", "left", "right"});
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].name, "camera_recall");
  EXPECT_FALSE(r[0].passed);
  EXPECT_EQ(r[0].message, "lowest mean recall of one camera (left) 0.7900, required >= 0.8000");
  EXPECT_EQ(r[1].name, "costmap_ghosts");
  EXPECT_FALSE(r[1].passed);
  EXPECT_THAT(r[1].message, HasSubstr("0 lethal cells without voxels and 1 columns of voxels without a lethal cell"));
  s.mean.camera_recall = {0.99, 0.81};
  s.mean.max_columns_without_lethal = 0;
  r = evaluation_checks(c, s, {"front", "left"});
  EXPECT_TRUE(r[0].passed);
  EXPECT_TRUE(r[1].passed);
  s.mean.max_lethal_without_voxels = 2;
  EXPECT_FALSE(evaluation_checks(c, s)[1].passed);
}

TEST(Checks, OneResultPerThresholdInOrderWithValueAndThreshold) {
  ChecksConfig c;
  c.f1_3d_min = 0.85;
  c.iou_3d_min = 0.6;
  c.all_obstacles_detected = true;
  c.phantom_obstacles_max = 2;
  c.clearing_latency_max_s = 0.2;
  c.accuracy_p90_max_m = 0.05;
  const auto r = evaluation_checks(c, summary());
  ASSERT_EQ(r.size(), 6u);
  EXPECT_EQ(r[0].name, "f1_3d");
  EXPECT_TRUE(r[0].passed);
  EXPECT_EQ(r[0].message, "mean 3D F1 0.9871, required >= 0.8500");
  EXPECT_FALSE(r[1].passed);
  EXPECT_EQ(r[1].message, "mean 3D IoU 0.5000, required >= 0.6000");
  EXPECT_FALSE(r[2].passed);
  EXPECT_EQ(r[2].message, "missed: door");  // "far" was never observed: not counted
  EXPECT_TRUE(r[3].passed);
  EXPECT_EQ(r[3].message, "2 phantom obstacles in the final costmap, allowed 2");
  EXPECT_FALSE(r[4].passed);
  EXPECT_EQ(r[4].message, "max latency 0.250 s, required <= 0.200 s (0 never cleared)");
  EXPECT_TRUE(r[5].passed);
  EXPECT_EQ(r[5].message, "p90 distance to the true surface 0.0310 m, required <= 0.0500 m");
  EXPECT_TRUE(evaluation_checks({}, summary()).empty());
}

TEST(Checks, ClearingWithNothingSeenThroughIsNotEvaluatedAndSaysWhy) {
  ChecksConfig c;
  c.clearing_latency_max_s = 1.0;
  evaluation::EvaluationSummary s;
  const auto r = evaluation_checks(c, s);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_FALSE(r[0].evaluated);
  EXPECT_STREQ(check_status(r[0]), "not_evaluated");
  EXPECT_EQ(r[0].message, "not evaluated: no stale voxel of a moved body was seen through");
}

// Issue 31: a run of 2 s or less printed "mean 3D F1 0.0000" and failed although nothing was averaged.
TEST(Checks, MeanFiguresWithoutASnapshotAreNotEvaluatedNotZero) {
  ChecksConfig c;
  c.f1_3d_min = 0.85, c.iou_3d_min = 0.5, c.costmap_precision_min = 0.7, c.costmap_recall_min = 0.5;
  c.camera_recall_min = 0.8, c.all_obstacles_detected = true, c.accuracy_p90_max_m = 0.05;
  evaluation::EvaluationSummary s;  // mean.snapshots == 0, nothing observed, no mapped voxel
  const auto r = evaluation_checks(c, s);
  ASSERT_EQ(r.size(), 7u);
  for (const auto& check : r) {
    EXPECT_FALSE(check.evaluated) << check.name;
    EXPECT_THAT(check.message, HasSubstr("not evaluated")) << check.name;
  }
  s = summary();  // averaged: judged as before
  c = {};
  c.f1_3d_min = 0.85;
  EXPECT_TRUE(evaluation_checks(c, s)[0].evaluated);
  EXPECT_TRUE(evaluation_checks(c, s)[0].passed);
}

// Issue 31: the floor marked lethal ahead of the robot passed every check; path_free_lethal says where.
TEST(Checks, PathFreeLethalFailsOnTheWorstEvaluationAndSaysWhere) {
  ChecksConfig c;
  c.path_free_lethal_max = 0;
  evaluation::EvaluationSummary s;
  auto r = evaluation_checks(c, s);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_TRUE(r[0].passed);
  EXPECT_EQ(r[0].message, "at worst 0 lethal cells where the truth is free along the path, allowed 0");
  s.mean.max_path_block = {3145, 3.08, -0.33, 3.08};
  s.mean.max_path_block_time_s = 19.0;
  r = evaluation_checks(c, s);
  EXPECT_FALSE(r[0].passed);
  EXPECT_EQ(r[0].name, "path_free_lethal");
  EXPECT_EQ(r[0].message,
            "at worst 3145 lethal cells where the truth is free along the path (t = 19.0 s, the first "
            "at (3.08, -0.33) m, 3.08 m along the path), allowed 0");
}

// Issue 31: a robot that stops short says where, since when and what it touches.
TEST(Checks, ABlockedRobotIsDiagnosedOnThePathCheck) {
  const std::string blocked = blocked_diagnosis({0.0, 0.884}, 3.93, {0.0, 4.0}, {"desk_2", "walls"});
  EXPECT_EQ(blocked,
            "blocked at (0.00, 0.88) m since t = 3.9 s, 3.12 m short of the path's end, touching desk_2, walls");
  EXPECT_EQ(path_completed_check(false, 10, 10, 0, false, blocked).message,
            "did not reach the end of the path within 10.0 s: " + blocked);
  EXPECT_THAT(blocked_diagnosis({1, 1}, 2, {1, 1}, {}), HasSubstr("touching nothing"));
}

TEST(Checks, APathCutShortByDurationIsReportedNotFailedUnlessRequired) {
  const CheckResult cut = path_completed_check(false, 10, 10, 45);
  EXPECT_FALSE(cut.evaluated);
  EXPECT_EQ(cut.message,
            "not evaluated: the path's end was not reached within 10.0 s, the run cut short by --duration "
            "(the scenario runs 45.0 s; --require-path fails on it)");
  const CheckResult required = path_completed_check(false, 10, 10, 45, true);
  EXPECT_TRUE(required.evaluated);
  EXPECT_FALSE(required.passed);
  EXPECT_TRUE(path_completed_check(true, 8, 10, 45).passed);   // reached anyway: judged
  EXPECT_TRUE(path_completed_check(false, 45, 45).evaluated);  // the scenario's own duration: judged
}

TEST(Checks, SelfLethalCellsTakesTheWorstEvaluation) {
  ChecksConfig c;
  c.self_lethal_cells_max = 0;
  evaluation::EvaluationSummary s;
  auto r = evaluation_checks(c, s);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_TRUE(r[0].passed);
  s.mean.max_self_inside = 3, s.mean.max_self_ring = 1, s.mean.max_self_lethal = 4;
  r = evaluation_checks(c, s);
  EXPECT_FALSE(r[0].passed);
  EXPECT_EQ(r[0].name, "self_lethal_cells");
  EXPECT_EQ(r[0].message,
            "at worst 4 lethal cells on the robot (3 inside its footprint, 1 in the ring) at one "
            "evaluation, allowed 0");
  c.self_lethal_cells_max = 4;
  EXPECT_TRUE(evaluation_checks(c, s)[0].passed);
}

TEST(Checks, RobotAndPathMessagesCarryTheirTimes) {
  // These used a printf format with "%.0s" fed a double (undefined behaviour); now plain text.
  EXPECT_EQ(path_completed_check(true, 12.345, 30).message, "reached the end of the path at t = 12.35 s");
  const CheckResult late = path_completed_check(false, 30, 30);
  EXPECT_FALSE(late.passed);
  EXPECT_EQ(late.message, "did not reach the end of the path within 30.0 s");
  const CheckResult fell = robot_upright_check(false, 4.5, 1.25);
  EXPECT_FALSE(fell.passed);
  EXPECT_EQ(fell.message, "the robot fell over or left the world at t = 4.50 s (tilt 1.25 rad)");
  EXPECT_TRUE(robot_upright_check(true, 1, 0).passed);
  EXPECT_EQ(fixed(0.5, 0), "0");  // round half to even, as printf
}

TEST(Checks, HiddenFalseClearsAboveTheBoundFailWithTheirFirstTime) {
  ChecksConfig c;
  c.hidden_false_clears_max = 0;
  evaluation::EvaluationSummary s = summary();
  auto r = evaluation_checks(c, s);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].name, "hidden_false_clears");
  EXPECT_TRUE(r[0].passed);
  EXPECT_EQ(r[0].message, "0 true voxels cleared while the camera did not see them, allowed 0");
  s.occlusion.hidden_false_clears = 1;
  s.occlusion.first_s = 5.25;
  r = evaluation_checks(c, s);
  EXPECT_FALSE(r[0].passed);
  EXPECT_EQ(r[0].message, "1 true voxels cleared while the camera did not see them (first at t = 5.25 s), allowed 0");
  c.hidden_false_clears_max = 1;
  EXPECT_TRUE(evaluation_checks(c, s)[0].passed);
}

// A 6-minute soak sampled each minute, first lap ending at 100 s (closed by the sample at 120 s); one lap spans
// 2 samples. Resident memory grows during the first lap (150 -> 200 MiB: the map and caches fill, not compared),
// then by rss_step_mb per sample; the map's CPU cost by map_step_ms per sample after the first lap (its wall-clock
// cost jumps about with the machine's load and must not count).
SoakSeries soak(double rss_step_mb, double map_step_ms) {
  SoakSeries s;
  s.sample_every_s = 60;
  s.laps = 3;
  s.first_lap_end_s = 100.0;
  s.first_lap_map_ms = 5.0;
  s.first_lap_map_cpu_ms = 2.0;
  for (int i = 1; i <= 6; ++i) {
    const int after = std::max(0, i - 2);
    const double wall_ms = i % 2 ? 3.0 : 12.0;
    s.samples.push_back(
        {60.0 * i, 1000u, 10u, i == 1 ? 150.0 : 200.0 + rss_step_mb * after, wall_ms, 2.0 + map_step_ms * after});
  }
  return s;
}

ChecksConfig soak_thresholds() {
  ChecksConfig c;
  c.soak_rss_growth_max = 0.10;
  c.soak_map_ms_growth_max = 0.5;
  return c;
}

TEST(Checks, SoakPassesWhenFlatAndSaysWhatItCompared) {
  const auto r = soak_checks(soak_thresholds(), soak(0.0, 0.0));
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].name, "soak_rss_growth");
  EXPECT_TRUE(r[0].passed) << r[0].message;
  EXPECT_THAT(r[0].message, HasSubstr("200.0 MiB at the end of the first lap (t = 120 s): 0.0 %, allowed 10.0 %"));
  EXPECT_EQ(r[1].name, "soak_map_ms_growth");
  EXPECT_TRUE(r[1].passed) << r[1].message;
  EXPECT_THAT(r[1].message,
              HasSubstr("2.000 ms CPU per frame over the last 2 samples vs 2.000 ms over the first lap: 0.0 %, "
                        "allowed 50.0 % (wall clock 7.500 vs 5.000 ms)"));
  EXPECT_TRUE(soak_checks(ChecksConfig{}, soak(100.0, 100.0)).empty());
}

TEST(Checks, SoakFailsOnGrowthOverTheMarginOnly) {
  // 4 samples after the one closing the first lap: peak 200 + 4 * 5.1 = 220.4 MiB (+10.2 %) fails, 4.9 (+9.8 %) passes.
  auto r = soak_checks(soak_thresholds(), soak(5.1, 0.0));
  EXPECT_FALSE(r[0].passed);
  EXPECT_THAT(r[0].message, HasSubstr("at most 220.4 MiB (t = 360 s)"));
  EXPECT_TRUE(soak_checks(soak_thresholds(), soak(4.9, 0.0))[0].passed);
  // Map cost: the last 2 samples 2 + 3 s and 2 + 4 s: mean 2 + 3.5 s; s = 0.3 ms gives 3.05 ms (+52.5 %) > 50 %.
  r = soak_checks(soak_thresholds(), soak(0.0, 0.3));
  EXPECT_FALSE(r[1].passed);
  EXPECT_THAT(r[1].message,
              HasSubstr("3.050 ms CPU per frame over the last 2 samples vs 2.000 ms over the first lap: 52.5 %"));
  EXPECT_TRUE(soak_checks(soak_thresholds(), soak(0.0, 0.28))[1].passed);
}

TEST(Checks, SoakTooShortFailsAndSaysWhy) {
  SoakSeries no_lap = soak(0.0, 0.0);
  no_lap.first_lap_end_s.reset();
  auto r = soak_checks(soak_thresholds(), no_lap);
  EXPECT_FALSE(r[0].passed);
  EXPECT_THAT(r[0].message, HasSubstr("the first lap was not completed"));
  SoakSeries late_lap = soak(0.0, 0.0);
  late_lap.first_lap_end_s = 330.0;  // closed by the last sample (360 s): nothing after it
  r = soak_checks(soak_thresholds(), late_lap);
  EXPECT_FALSE(r[0].passed);
  EXPECT_THAT(r[0].message, HasSubstr("no sample after the one closing the first lap"));
  SoakSeries long_lap = soak(0.0, 0.0);
  long_lap.first_lap_end_s = 170.0;  // one lap spans 3 samples; only 3 after the one at 180 s: enough
  EXPECT_TRUE(soak_checks(soak_thresholds(), long_lap)[1].passed);
  long_lap.first_lap_end_s = 230.0;  // spans 4; 2 after the one at 240 s
  r = soak_checks(soak_thresholds(), long_lap);
  EXPECT_FALSE(r[1].passed);
  EXPECT_THAT(r[1].message, HasSubstr("fewer samples after the first lap (2) than one lap spans (4)"));
}

}  // namespace
}  // namespace stvl::evaluation

#include "tools/checks.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace stvl::tools {
namespace {

using ::testing::HasSubstr;

evaluation::EvaluationSummary summary() {
  evaluation::EvaluationSummary s;
  s.mean.f1 = 0.9871;
  s.mean.iou = 0.5;
  s.final.phantom_obstacles = 2;
  s.obstacles = {{"box", 10, 8, 0.9, true, true}, {"door", 10, 6, 0.2, true, false}, {"far", 10, 0, 0, false, false}};
  s.clearing.stale_voxels_seen_through = 5;
  s.clearing.max_latency_s = 0.25;
  s.accuracy.p90_m = 0.031;
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

TEST(Checks, ClearingWithNothingSeenThroughFailsAndSaysWhy) {
  ChecksConfig c;
  c.clearing_latency_max_s = 1.0;
  evaluation::EvaluationSummary s;
  const auto r = evaluation_checks(c, s);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_FALSE(r[0].passed);
  EXPECT_EQ(r[0].message, "no stale voxel of a moved body was seen through");
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
  EXPECT_EQ(r[0].message, "at worst 4 lethal cells on the robot (3 inside its footprint, 1 in the ring) at one "
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

}  // namespace
}  // namespace stvl::tools

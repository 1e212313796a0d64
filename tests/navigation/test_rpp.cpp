// nav2's Regulated Pure Pursuit (navigation/rpp.hpp) against numbers worked by hand from jazzy f4108e5b1's
// regulated_pure_pursuit_controller.cpp, regulation_functions.hpp, path_handler.cpp and collision_checker.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "navigation/rpp.hpp"

namespace stvl::navigation {
namespace {

constexpr double kDt = 0.05;  // controller_frequency 20 Hz

// 100 x 100 free cells of 5 cm centred on the origin: [-2.5, 2.5) in x and y.
mapping::Costmap2D free_map() {
  mapping::Costmap2D map;
  map.width = 100;
  map.height = 100;
  map.resolution_m = 0.05;
  map.origin_m = Eigen::Vector2d(-2.5, -2.5);
  map.cells.assign(100 * 100, mapping::kCostFree);
  return map;
}

void set_cell_at(mapping::Costmap2D& map, double x_m, double y_m, std::uint8_t cost) {
  const int ix = static_cast<int>((x_m - map.origin_m.x()) / map.resolution_m);
  const int iy = static_cast<int>((y_m - map.origin_m.y()) / map.resolution_m);
  map.cells[static_cast<std::size_t>(iy) * map.width + ix] = cost;
}

// Poses every step_m along the ray from `from` with heading yaw_rad, length_m long.
std::vector<Pose2> ray(Eigen::Vector2d from, double yaw_rad, double length_m, double step_m = 0.05) {
  std::vector<Pose2> path;
  const int n = static_cast<int>(std::round(length_m / step_m));
  for (int i = 0; i <= n; ++i) {
    path.push_back({from.x() + i * step_m * std::cos(yaw_rad), from.y() + i * step_m * std::sin(yaw_rad), yaw_rad});
  }
  return path;
}

RppParams plain_params() {
  RppParams p;
  p.use_cost_regulated_linear_velocity_scaling = false;
  return p;
}

RegulatedPurePursuit make(const RppParams& p, LocalCostmapConfig c = {}) { return RegulatedPurePursuit(p, c); }

TEST(Rpp, DefaultsAreJazzys) {
  const RppParams p;
  EXPECT_EQ(p.desired_linear_vel, 0.5);
  EXPECT_EQ(p.lookahead_dist, 0.6);
  EXPECT_EQ(p.rotate_to_heading_min_angle, 0.785);
  EXPECT_EQ(p.max_angular_accel, 3.2);
  EXPECT_TRUE(p.use_cost_regulated_linear_velocity_scaling);
  EXPECT_TRUE(p.use_collision_detection);
  EXPECT_TRUE(p.stateful);
  EXPECT_FALSE(p.max_robot_pose_search_dist.has_value());
  EXPECT_NO_THROW(p.validate());
}

TEST(Rpp, StraightPathDrivesAtDesiredSpeed) {
  auto rpp = make(plain_params());
  rpp.set_plan(ray({0, 0}, 0.0, 2.0));
  const RppCommand c = rpp.compute({0, 0, 0}, {}, free_map(), kDt, 0.25);
  ASSERT_EQ(c.status, RppStatus::kOk) << c.message;
  EXPECT_DOUBLE_EQ(c.twist.v_mps, 0.5);
  EXPECT_DOUBLE_EQ(c.twist.omega_radps, 0.0);
  EXPECT_NEAR(c.carrot_W.x(), 0.6, 1e-12);
  EXPECT_NEAR(c.carrot_W.y(), 0.0, 1e-12);
  EXPECT_FALSE(c.rotating_to_heading);
}

TEST(Rpp, ThePlanInMapIsFollowedThroughTheLocalizersPose) {
  // The plan y = 0 in map; the localizer has the robot 0.3 m to its left (robot_plan) while odometry's pose is on
  // it: the plan lies 0.3 m to the robot's right, the carrot where the 0.6 m circle meets it, (0.519615, -0.3) from
  // the robot, curvature 2 * -0.3 / 0.36; the costmap's side keeps robot_W.
  auto rpp = make(plain_params());
  rpp.set_plan(ray({0, 0}, 0.0, 2.0));
  const RppCommand c = rpp.compute({0, 0, 0}, {}, free_map(), kDt, 0.25, Pose2{0, 0.3, 0});
  ASSERT_EQ(c.status, RppStatus::kOk) << c.message;
  EXPECT_NEAR(c.carrot_W.x(), std::sqrt(0.36 - 0.09), 1e-6);
  EXPECT_NEAR(c.carrot_W.y(), -0.3, 1e-6);
  EXPECT_NEAR(c.curvature_per_m, -0.6 / 0.36, 1e-6);
  EXPECT_LT(c.twist.omega_radps, -0.1);
  auto on_it = make(plain_params());
  on_it.set_plan(ray({0, 0}, 0.0, 2.0));
  EXPECT_DOUBLE_EQ(on_it.compute({0, 0, 0}, {}, free_map(), kDt, 0.25, Pose2{0, 0, 0}).twist.omega_radps, 0.0);
}

TEST(Rpp, LeftCurveCarrotCurvatureAndOmega) {
  // The line y = x / 2: the carrot is 0.6 * (2, 1) / sqrt(5) = (0.536656, 0.268328), curvature 2y / L^2 =
  // 1.490712 (radius 0.670820 < 0.9), so v = 0.5 * 0.670820 / 0.9 = 0.372678 and omega = v * k = 0.5 / 0.9.
  auto rpp = make(plain_params());
  rpp.set_plan({{0, 0, 0}, {0.4, 0.2, 0}, {0.8, 0.4, 0}});
  const RppCommand c = rpp.compute({0, 0, 0}, {}, free_map(), kDt, 0.25);
  ASSERT_EQ(c.status, RppStatus::kOk) << c.message;
  EXPECT_NEAR(c.carrot_W.x(), 0.536656, 1e-6);
  EXPECT_NEAR(c.carrot_W.y(), 0.268328, 1e-6);
  EXPECT_NEAR(c.curvature_per_m, 1.490712, 1e-6);
  EXPECT_NEAR(c.twist.v_mps, 0.372678, 1e-6);
  EXPECT_NEAR(c.twist.omega_radps, 0.5 / 0.9, 1e-9);
}

TEST(Rpp, CurvatureRegulationFlooredAtMinSpeed) {
  // Lookahead 0.3 on a ray at 0.7 rad: k = 2 sin(0.7) / 0.3 = 4.294784, radius 0.232840, v = 0.5 * 0.232840 /
  // 0.9 = 0.129356 -> floored at regulated_linear_scaling_min_speed 0.25; omega = 0.25 * k = 1.073696.
  RppParams p = plain_params();
  p.lookahead_dist = 0.3;
  auto rpp = make(p);
  rpp.set_plan(ray({0, 0}, 0.7, 2.0, 0.1));
  const RppCommand c = rpp.compute({0, 0, 0}, {}, free_map(), kDt, 0.25);
  ASSERT_EQ(c.status, RppStatus::kOk) << c.message;
  EXPECT_NEAR(c.curvature_per_m, 4.294784, 1e-6);
  EXPECT_DOUBLE_EQ(c.twist.v_mps, 0.25);
  EXPECT_NEAR(c.twist.omega_radps, 1.073696, 1e-6);

  // Scaling off: the full speed on the same arc.
  p.use_regulated_linear_velocity_scaling = false;
  auto unregulated = make(p);
  unregulated.set_plan(ray({0, 0}, 0.7, 2.0, 0.1));
  EXPECT_DOUBLE_EQ(unregulated.compute({0, 0, 0}, {}, free_map(), kDt, 0.25).twist.v_mps, 0.5);
}

TEST(Rpp, RotatesTowardsAPathBehindWithinTheAccelerationLimit) {
  // Carrot (-0.6, 0): angle pi > 0.785, so turn left at 1.8 rad/s clamped to omega0 +- 3.2 * 0.05.
  auto rpp = make(plain_params());
  const auto path = ray({0, 0}, M_PI, 2.0);
  rpp.set_plan(path);
  RppCommand c = rpp.compute({0, 0, 0}, {}, free_map(), kDt, 0.25);
  ASSERT_EQ(c.status, RppStatus::kOk) << c.message;
  EXPECT_TRUE(c.rotating_to_heading);
  EXPECT_EQ(c.twist.v_mps, 0.0);
  EXPECT_NEAR(c.twist.omega_radps, 0.16, 1e-12);
  rpp.set_plan(path);
  c = rpp.compute({0, 0, 0}, {0.0, 1.0}, free_map(), kDt, 0.25);
  EXPECT_NEAR(c.twist.omega_radps, 1.16, 1e-12);
  rpp.set_plan(path);
  c = rpp.compute({0, 0, 0}, {0.0, 1.75}, free_map(), kDt, 0.25);
  EXPECT_NEAR(c.twist.omega_radps, 1.8, 1e-12);

  // A path to the right (carrot (0, -0.6), -pi/2): turn right.
  rpp.set_plan(ray({0, 0}, -M_PI / 2, 2.0));
  c = rpp.compute({0, 0, 0}, {}, free_map(), kDt, 0.25);
  EXPECT_NEAR(c.twist.omega_radps, -0.16, 1e-12);
}

TEST(Rpp, GoalHeadingNearTheGoalSlowsToStopOnTheAngle) {
  // Robot on the last pose (goal yaw 0.1): carrot 0 < 0.25 -> rotate to 0.1 rad; from omega0 = 1.0 the
  // acceleration limit gives 1.16, above sqrt(2 * 3.2 * 0.1) = 0.8, the speed that stops on the angle.
  auto rpp = make(plain_params());
  auto path = ray({-1.0, 0}, 0.0, 1.0);
  path.back().yaw_rad = 0.1;
  rpp.set_plan(path);
  RppCommand c = rpp.compute({0, 0, 0}, {0.0, 1.0}, free_map(), kDt, 0.25);
  ASSERT_EQ(c.status, RppStatus::kOk) << c.message;
  EXPECT_TRUE(c.rotating_to_heading);
  EXPECT_EQ(c.twist.v_mps, 0.0);
  EXPECT_NEAR(c.twist.omega_radps, 0.8, 1e-12);
  // The 2-pose minimum: the closest (last) pose keeps the one before it.
  EXPECT_EQ(rpp.plan_W().size(), 2u);

  // Stateful: latched, even when the carrot is back outside the tolerance.
  c = rpp.compute({-0.5, 0, 0}, {}, free_map(), kDt, 0.25);
  EXPECT_TRUE(c.rotating_to_heading);
  EXPECT_EQ(c.twist.v_mps, 0.0);
}

TEST(Rpp, StatefulLatchClearedBySetPlanAndOffWhenNotStateful) {
  RppParams p = plain_params();
  auto rpp = make(p);
  rpp.set_plan(ray({0, 0}, 0.0, 2.0));
  // Near the end: carrot = last pose (2.0, 0) at 0.1 m.
  EXPECT_TRUE(rpp.compute({1.9, 0, 0}, {}, free_map(), kDt, 0.25).rotating_to_heading);
  rpp.set_plan(ray({0, 0}, 0.0, 2.0));
  EXPECT_FALSE(rpp.compute({0, 0, 0}, {}, free_map(), kDt, 0.25).rotating_to_heading);

  p.stateful = false;
  auto stateless = make(p);
  stateless.set_plan(ray({0, 0}, 0.0, 2.0));
  EXPECT_TRUE(stateless.compute({1.9, 0, 0}, {}, free_map(), kDt, 0.25).rotating_to_heading);
  // Not stateful: backing off the goal drives again (the plan's last two poses remain).
  const RppCommand c = stateless.compute({1.5, 0, 0}, {}, free_map(), kDt, 0.25);
  EXPECT_FALSE(c.rotating_to_heading);
  EXPECT_GT(c.twist.v_mps, 0.0);
}

TEST(Rpp, ApproachScalingNearTheEnd) {
  // Path 0.4 m long < approach_velocity_scaling_dist 0.6: v = 0.5 * 0.4 / 0.6.
  auto rpp = make(plain_params());
  rpp.set_plan(ray({0, 0}, 0.0, 0.4));
  RppCommand c = rpp.compute({0, 0, 0}, {}, free_map(), kDt, 0.25);
  ASSERT_EQ(c.status, RppStatus::kOk) << c.message;
  EXPECT_NEAR(c.carrot_W.x(), 0.4, 1e-12);
  EXPECT_NEAR(c.twist.v_mps, 0.5 * 0.4 / 0.6, 1e-12);
  // 0.05 m left with a small goal tolerance: 0.5 * 0.05 / 0.6 = 0.0417 -> min_approach_linear_velocity 0.05.
  rpp.set_plan(ray({0, 0}, 0.0, 0.05));
  c = rpp.compute({0, 0, 0}, {}, free_map(), kDt, 0.01);
  EXPECT_NEAR(c.twist.v_mps, 0.05, 1e-12);
}

TEST(Rpp, CostRegulationFromTheInflationDecay) {
  // Square footprint +-0.2 unpadded: inscribed 0.2. Cost 100 at the robot: d = (3 * 0.2 - ln 100 + ln 253) / 3
  // = 0.509406 < 0.6 -> v = 0.5 * 0.509406 / 0.6 = 0.424505.
  LocalCostmapConfig shape;
  shape.footprint_m = {{0.2, 0.2}, {-0.2, 0.2}, {-0.2, -0.2}, {0.2, -0.2}};
  shape.footprint_padding_m = 0.0;
  RppParams p;  // cost regulation on, jazzy's default
  auto rpp = make(p, shape);
  EXPECT_DOUBLE_EQ(rpp.inscribed_radius_m(), 0.2);
  EXPECT_DOUBLE_EQ(rpp.circumscribed_radius_m(), std::hypot(0.2, 0.2));
  auto map = free_map();
  set_cell_at(map, 0.01, 0.01, 100);
  rpp.set_plan(ray({0, 0}, 0.0, 2.0));
  const RppCommand c = rpp.compute({0.01, 0.01, 0}, {}, map, kDt, 0.25);
  ASSERT_EQ(c.status, RppStatus::kOk) << c.message;
  EXPECT_NEAR(c.twist.v_mps, 0.424505, 1e-6);
}

TEST(Rpp, RadiusFootprintIsNav2sPaddedSixteenGon) {
  LocalCostmapConfig shape;
  shape.robot_radius_m = 0.2;
  shape.footprint_padding_m = 0.0;
  auto rpp = make(plain_params(), shape);
  ASSERT_EQ(rpp.footprint_m().size(), 16u);
  EXPECT_NEAR(rpp.inscribed_radius_m(), 0.2 * std::cos(M_PI / 16), 1e-12);
  EXPECT_NEAR(rpp.circumscribed_radius_m(), 0.2, 1e-12);
  // Default padding 0.01 (as a float) pushes each non-zero coordinate outwards: (0.2, ~0) -> (0.21, ~0.01).
  auto padded = make(plain_params(), LocalCostmapConfig{{}, 0.2, 0.01, false});
  EXPECT_NEAR(padded.footprint_m()[0].x(), 0.21, 1e-8);
  EXPECT_EQ(padded.footprint_m()[0].y(), 0.0);
  EXPECT_NEAR(padded.footprint_m()[4].x(), 0.01, 1e-8);  // cos(pi / 2) is 6e-17 > 0
}

TEST(Rpp, CollisionAheadStopsWithNav2sMessage) {
  // v = 0.5, steps of one cell (0.1 s) while i * 0.1 < 1.0: nine steps to x = 0.45; the padded radius-0.1
  // footprint's front reaches 0.56, into the lethal wall at x >= 0.5.
  auto map = free_map();
  for (double y = -2.45; y < 2.5; y += 0.05) set_cell_at(map, 0.52, y, mapping::kCostLethal);
  auto rpp = make(plain_params());
  rpp.set_plan(ray({0, 0}, 0.0, 2.0));
  const RppCommand c = rpp.compute({0, 0, 0}, {}, map, kDt, 0.25);
  EXPECT_EQ(c.status, RppStatus::kCollisionAhead);
  EXPECT_EQ(c.message, "RegulatedPurePursuitController detected collision ahead!");
  EXPECT_EQ(c.twist.v_mps, 0.0);
  EXPECT_EQ(c.twist.omega_radps, 0.0);

  // The same wall at x = 0.7 is beyond the projected footprint: no collision.
  auto far_map = free_map();
  for (double y = -2.45; y < 2.5; y += 0.05) set_cell_at(far_map, 0.72, y, mapping::kCostLethal);
  rpp.set_plan(ray({0, 0}, 0.0, 2.0));
  EXPECT_EQ(rpp.compute({0, 0, 0}, {}, far_map, kDt, 0.25).status, RppStatus::kOk);

  // use_collision_detection off: drives on.
  RppParams p = plain_params();
  p.use_collision_detection = false;
  auto blind = make(p);
  blind.set_plan(ray({0, 0}, 0.0, 2.0));
  EXPECT_DOUBLE_EQ(blind.compute({0, 0, 0}, {}, map, kDt, 0.25).twist.v_mps, 0.5);
}

TEST(Rpp, FootprintCostRasterisesEdgesOnly) {
  auto map = free_map();
  const std::vector<Eigen::Vector2d> square = {{0.2, 0.2}, {-0.2, 0.2}, {-0.2, -0.2}, {0.2, -0.2}};
  set_cell_at(map, 0.01, 0.01, mapping::kCostLethal);  // inside, off the edges
  EXPECT_EQ(footprint_cost_at_pose(map, {0, 0, 0}, square), 0.0);
  set_cell_at(map, 0.21, 0.01, 200);  // on the right edge
  EXPECT_EQ(footprint_cost_at_pose(map, {0, 0, 0}, square), 200.0);
  set_cell_at(map, -0.19, -0.21, mapping::kCostLethal);  // on the bottom edge
  EXPECT_EQ(footprint_cost_at_pose(map, {0, 0, 0}, square), 254.0);
  // A vertex off the map is lethal.
  EXPECT_EQ(footprint_cost_at_pose(free_map(), {2.4, 0, 0}, square), 254.0);
}

TEST(Rpp, CollisionProjectionStopsBeforeTheTimeLimit) {
  // Steps of 0.1 s while i * 0.1 < 1.0: the ninth and last puts the front vertex (0.45 + 0.11) in the cell
  // [0.55, 0.60); a wall one cell further, [0.60, 0.65), is not checked. Inscribed (253) cells never collide.
  auto wall_at = [](double x_m, std::uint8_t cost) {
    auto map = free_map();
    for (double y = -2.45; y < 2.5; y += 0.05) set_cell_at(map, x_m, y, cost);
    return map;
  };
  auto rpp = make(plain_params());
  auto status_with = [&](const mapping::Costmap2D& map) {
    rpp.set_plan(ray({0, 0}, 0.0, 2.0));
    return rpp.compute({0, 0, 0}, {}, map, kDt, 0.25).status;
  };
  EXPECT_EQ(status_with(wall_at(0.57, mapping::kCostLethal)), RppStatus::kCollisionAhead);
  EXPECT_EQ(status_with(wall_at(0.62, mapping::kCostLethal)), RppStatus::kOk);
  EXPECT_EQ(status_with(wall_at(0.57, 253)), RppStatus::kOk);
}

TEST(Rpp, FootprintEdgeFollowsNav2sLineIterator) {
  // Cells (50, 50) -> (53, 51): Bresenham visits (50,50), (51,50), (52,51), (53,51), not (51,51).
  auto map = free_map();
  map.cells[50 * 100 + 51] = 100;
  map.cells[51 * 100 + 51] = 200;
  EXPECT_EQ(footprint_cost_at_pose(map, {0, 0, 0}, {{0.025, 0.025}, {0.175, 0.075}}), 100.0);
  map.cells[51 * 100 + 52] = 150;
  EXPECT_EQ(footprint_cost_at_pose(map, {0, 0, 0}, {{0.025, 0.025}, {0.175, 0.075}}), 150.0);
}

TEST(Rpp, ClosestPoseTiesGoToTheLaterPose) {
  // Poses at x = -0.1, 0.1, 0.3, ...: the robot at 0 is 0.1 from the first two; nav2's min_by keeps the later.
  auto rpp = make(plain_params());
  rpp.set_plan(ray({-0.1, 0}, 0.0, 2.0, 0.2));
  ASSERT_EQ(rpp.compute({0, 0, 0}, {}, free_map(), kDt, 0.25).status, RppStatus::kOk);
  EXPECT_NEAR(rpp.plan_W().front().x_m, 0.1, 1e-12);
}

TEST(Rpp, UnknownCellsCollideUnlessTracked) {
  auto map = free_map();
  for (double y = -2.45; y < 2.5; y += 0.05) set_cell_at(map, 0.52, y, mapping::kCostUnknown);
  auto rpp = make(plain_params());
  rpp.set_plan(ray({0, 0}, 0.0, 2.0));
  EXPECT_EQ(rpp.compute({0, 0, 0}, {}, map, kDt, 0.25).status, RppStatus::kCollisionAhead);
  auto tracking = make(plain_params(), LocalCostmapConfig{{}, 0.1, 0.01, true});
  tracking.set_plan(ray({0, 0}, 0.0, 2.0));
  EXPECT_EQ(tracking.compute({0, 0, 0}, {}, map, kDt, 0.25).status, RppStatus::kOk);
}

TEST(Rpp, LookaheadPointLiesExactlyOnTheCircle) {
  EXPECT_TRUE(circle_segment_intersection({0.3, 0.0}, {0.3, 1.0}, 0.5).isApprox(Eigen::Vector2d(0.3, 0.4), 1e-15));
  // Robot at (0.5, 0.3) heading 0.4 rad, a bent plan: the carrot is 0.6 m from the robot, on the segment
  // between the last pose inside the circle and the first outside it.
  const Pose2 robot{0.5, 0.3, 0.4};
  const std::vector<Pose2> plan = {{0.5, 0.3, 0}, {0.8, 0.5, 0}, {1.0, 1.2, 0}, {1.1, 1.9, 0}};
  auto rpp = make(plain_params());
  rpp.set_plan(plan);
  const RppCommand c = rpp.compute(robot, {}, free_map(), kDt, 0.25);
  const Eigen::Vector2d a(0.8, 0.5), b(1.0, 1.2);
  EXPECT_NEAR((c.carrot_W - Eigen::Vector2d(robot.x_m, robot.y_m)).norm(), 0.6, 1e-12);
  const Eigen::Vector2d ab = b - a, ac = c.carrot_W - a;
  EXPECT_NEAR(ab.x() * ac.y() - ab.y() * ac.x(), 0.0, 1e-12);
  EXPECT_GT(ac.dot(ab), 0.0);
  EXPECT_LT(ac.norm(), ab.norm());
}

TEST(Rpp, VelocityScaledLookaheadIsClamped) {
  RppParams p = plain_params();
  p.use_velocity_scaled_lookahead_dist = true;
  auto rpp = make(p);
  auto lookahead_at = [&](double v) {
    rpp.set_plan(ray({0, 0}, 0.0, 2.0));
    return rpp.compute({0, 0, 0}, {v, 0.0}, free_map(), kDt, 0.25).lookahead_m;
  };
  EXPECT_DOUBLE_EQ(lookahead_at(0.1), 0.3);    // 0.15 -> min_lookahead_dist
  EXPECT_NEAR(lookahead_at(0.4), 0.6, 1e-12);  // 0.4 * 1.5
  EXPECT_NEAR(lookahead_at(-0.4), 0.6, 1e-12);
  EXPECT_DOUBLE_EQ(lookahead_at(1.0), 0.9);  // 1.5 -> max_lookahead_dist
}

TEST(Rpp, PrunesThePlanBehindTheRobot) {
  auto rpp = make(plain_params());
  rpp.set_plan(ray({0, 0}, 0.0, 2.0));  // 41 poses
  ASSERT_EQ(rpp.compute({1.0, 0.02, 0}, {}, free_map(), kDt, 0.25).status, RppStatus::kOk);
  ASSERT_EQ(rpp.plan_W().size(), 21u);  // poses from x = 1.0 on
  EXPECT_NEAR(rpp.plan_W().front().x_m, 1.0, 1e-12);
}

TEST(Rpp, ClosestPoseSearchIsBoundedAlongThePlan) {
  // Out along y = 0 to x = 1.5 and back along y = 0.1: the robot at (0, 0.07) is nearest the return leg's end,
  // but the search stops after max_robot_pose_search_dist of path, so the plan's start stays the closest pose.
  auto loop = ray({0, 0}, 0.0, 1.5);
  for (const Pose2& q : ray({1.5, 0.1}, M_PI, 1.5)) loop.push_back(q);
  ASSERT_EQ(loop.size(), 62u);
  RppParams p = plain_params();
  p.max_robot_pose_search_dist = 1.0;
  auto bounded = make(p);
  bounded.set_plan(loop);
  bounded.compute({0, 0.07, 0}, {}, free_map(), kDt, 0.25);
  EXPECT_EQ(bounded.plan_W().size(), 62u);
  p.max_robot_pose_search_dist = -1.0;  // the whole plan
  auto unbounded = make(p);
  unbounded.set_plan(loop);
  unbounded.compute({0, 0.07, 0}, {}, free_map(), kDt, 0.25);
  EXPECT_EQ(unbounded.plan_W().size(), 2u);  // the closest (last) pose and the one before it
}

TEST(Rpp, ReversingFollowsAPathBehindAndStopsAtTheCusp) {
  RppParams p = plain_params();
  p.allow_reversing = true;
  p.use_rotate_to_heading = false;
  auto rpp = make(p);
  rpp.set_plan(ray({0, 0}, M_PI, 2.0));
  RppCommand c = rpp.compute({0, 0, 0}, {}, free_map(), kDt, 0.25);
  ASSERT_EQ(c.status, RppStatus::kOk) << c.message;
  EXPECT_DOUBLE_EQ(c.twist.v_mps, -0.5);
  EXPECT_NEAR(c.twist.omega_radps, 0.0, 1e-12);
  // Forward to x = 0.3, then back from 0.27 (never through the robot's x = 0 exactly: nav2's closest-pose
  // search keeps the last of equal distances): the lookahead shrinks to the cusp's distance 0.3.
  auto there_and_back = ray({0, 0}, 0.0, 0.3);
  for (const Pose2& q : ray({0.27, 0}, M_PI, 1.0)) there_and_back.push_back({q.x_m, q.y_m, 0.0});
  rpp.set_plan(there_and_back);
  c = rpp.compute({0, 0, 0}, {}, free_map(), kDt, 0.25);
  EXPECT_NEAR(c.lookahead_m, 0.3, 1e-12);
  EXPECT_GT(c.twist.v_mps, 0.0);
}

TEST(Rpp, ErrorsAsNav2Throws) {
  auto rpp = make(plain_params());
  RppCommand c = rpp.compute({0, 0, 0}, {}, free_map(), kDt, 0.25);
  EXPECT_EQ(c.status, RppStatus::kNoPath);
  EXPECT_EQ(c.message, "Received plan with zero length");
  // A robot off the local costmap while regulating.
  rpp.set_plan(ray({3.0, 0}, 0.0, 1.0));
  c = rpp.compute({3.0, 0, 0}, {}, free_map(), kDt, 0.25);
  EXPECT_EQ(c.status, RppStatus::kCostmapTooSmall);
  // Every pose beyond the costmap's half extent (99.5 * 0.05 / 2 = 2.4875 m).
  rpp.set_plan({{2.49, 0, 0}, {2.6, 0, 0}});
  c = rpp.compute({0, 0, 0}, {}, free_map(), kDt, 0.25);
  EXPECT_EQ(c.status, RppStatus::kInvalidPath);
  EXPECT_EQ(c.message, "Resulting plan has 0 poses in it.");
}

TEST(Rpp, CancelDecelerates) {
  RppParams p = plain_params();
  p.use_cancel_deceleration = true;
  auto rpp = make(p);
  rpp.set_plan(ray({0, 0}, 0.0, 2.0));
  EXPECT_FALSE(rpp.cancel());
  EXPECT_NEAR(rpp.compute({0, 0, 0}, {0.5, 0.0}, free_map(), kDt, 0.25).twist.v_mps, 0.5 - 0.05 * 3.2, 1e-12);
  EXPECT_FALSE(rpp.cancel());
  EXPECT_EQ(rpp.compute({0, 0, 0}, {0.1, 0.0}, free_map(), kDt, 0.25).twist.v_mps, 0.0);
  EXPECT_TRUE(rpp.cancel());
  EXPECT_TRUE(make(plain_params()).cancel());  // without deceleration: stop at once
}

TEST(Rpp, ValidateNamesTheKey) {
  auto expect_bad = [](RppParams p, const std::string& key) {
    try {
      p.validate();
      ADD_FAILURE() << "no throw for " << key;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  RppParams p;
  p.lookahead_dist = -0.1;
  expect_bad(p, "lookahead_dist");
  p = RppParams{};
  p.min_lookahead_dist = 1.0;
  expect_bad(p, "min_lookahead_dist");
  p = RppParams{};
  p.desired_linear_vel = std::numeric_limits<double>::quiet_NaN();
  expect_bad(p, "desired_linear_vel");
  p = RppParams{};
  p.max_robot_pose_search_dist = std::numeric_limits<double>::quiet_NaN();
  expect_bad(p, "max_robot_pose_search_dist");
  EXPECT_THROW(RegulatedPurePursuit(p, {}), std::invalid_argument);
  EXPECT_THROW(RegulatedPurePursuit(RppParams{}, LocalCostmapConfig{{{0.1, 0.0}, {0.0, 0.1}}, 0.1, 0.01, false}),
               std::invalid_argument);
  // nav2's configure-time corrections rather than errors.
  p = RppParams{};
  p.inflation_cost_scaling_factor = 0.0;
  p.interpolate_curvature_after_goal = true;
  p.max_robot_pose_search_dist = -1.0;
  const auto rpp = make(p);
  EXPECT_FALSE(rpp.params().use_cost_regulated_linear_velocity_scaling);
  EXPECT_FALSE(rpp.params().interpolate_curvature_after_goal);
  EXPECT_EQ(*rpp.params().max_robot_pose_search_dist, std::numeric_limits<double>::max());
}

}  // namespace
}  // namespace stvl::navigation

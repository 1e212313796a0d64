// nav2's default tree around NavFn, RPP and the behaviours (navigation/navigator.hpp), driving a unicycle that
// follows the commanded twist exactly, on hand-made static maps and layer grids.
#include <cmath>

#include <gtest/gtest.h>

#include "navigation/navigator.hpp"

namespace stvl::navigation {
namespace {

// A 10 x 4 m room at 0.05 m with walls around.
mapping::Costmap2D room() {
  mapping::Costmap2D m;
  m.width = 200, m.height = 80, m.resolution_m = 0.05;
  m.cells.assign(200 * 80, mapping::kCostFree);
  for (int x = 0; x < 200; ++x) m.cells[x] = m.cells[79 * 200 + x] = mapping::kCostLethal;
  for (int y = 0; y < 80; ++y) m.cells[y * 200] = m.cells[y * 200 + 199] = mapping::kCostLethal;
  return m;
}

NavigationConfig config(Pose2 goal) {
  NavigationConfig c;
  c.mode = NavigationMode::kClosedLoop;
  c.goal = goal;
  c.robot_radius_m = 0.2;
  c.local_costmap.inflation.inflation_radius_m = 0.5;
  c.global_costmap.inflation.inflation_radius_m = 0.5;
  return c;
}

// Drives the navigator for up to `seconds` at the controller's rate; the layer grid is `layer` throughout.
struct Drive {
  Navigator& nav;
  mapping::Costmap2D layer;
  Pose2 pose;
  double t = 0;
  bool layer_current = true;  // the 3D layer's isCurrent at each costmap update
  void run(double seconds) {
    const double dt = 1.0 / nav.config().controller_frequency_hz;
    Twist velocity;
    for (const double end = t + seconds; t < end && nav.status() == NavigationStatus::kRunning; t += dt) {
      nav.update_costmaps(t, layer, pose, true, true, layer_current);
      velocity = nav.tick(t, pose, velocity);
      pose.yaw_rad += velocity.omega_radps * dt;
      pose.x_m += velocity.v_mps * std::cos(pose.yaw_rad) * dt;
      pose.y_m += velocity.v_mps * std::sin(pose.yaw_rad) * dt;
    }
  }
};

std::vector<std::string> kinds(const Navigator& nav, const std::string& kind) {
  std::vector<std::string> out;
  for (const auto& e : nav.events())
    if (e.kind == kind) out.push_back(e.detail);
  return out;
}

mapping::Costmap2D empty_layer() {
  mapping::Costmap2D m;
  m.width = m.height = 1;
  m.origin_m = {-100, -100};
  m.cells = {mapping::kCostFree};
  return m;
}

TEST(Navigator, ReachesAGoalAcrossAnEmptyRoomAndReplansAtOneHertz) {
  Navigator nav(config({8.0, 2.0, 0.0}), room());
  Drive d{nav, empty_layer(), {1.0, 2.0, 0.0}};
  d.run(60);
  ASSERT_EQ(nav.status(), NavigationStatus::kSucceeded) << nav.failure();
  EXPECT_NEAR(d.pose.x_m, 8.0, 0.25);  // general_goal_checker: xy 0.25
  EXPECT_NEAR(d.pose.y_m, 2.0, 0.25);
  EXPECT_EQ(nav.recoveries(), 0);
  // 7 m at 0.5 m/s: about 15 s of driving, a plan each second.
  EXPECT_GT(nav.finished_at_s(), 13.0);
  EXPECT_LT(nav.finished_at_s(), 25.0);
  const auto plans = kinds(nav, "plan");
  EXPECT_NEAR(static_cast<double>(plans.size()), std::floor(nav.finished_at_s()) + 1, 1.0);
}

TEST(Navigator, AWallAcrossTheRoomRunsTheRecoveriesInNav2sOrderThenGivesUp) {
  mapping::Costmap2D blocked = room();
  for (int y = 0; y < 80; ++y) blocked.cells[y * 200 + 100] = mapping::kCostLethal;
  Navigator nav(config({8.0, 2.0, 0.0}), blocked);
  Drive d{nav, empty_layer(), {1.0, 2.0, 0.0}};
  d.run(200);
  ASSERT_EQ(nav.status(), NavigationStatus::kFailed);
  // Each pipeline failure: the planner's context clearing first, then a round robin recovery; 6 retries.
  const std::vector<std::string> expected{"clear", "spin", "wait", "backup", "clear", "spin"};
  EXPECT_EQ(kinds(nav, "recovery"), expected);
  EXPECT_EQ(nav.recoveries(), 6);
  EXPECT_NE(nav.failure().find("after 6 recoveries"), std::string::npos) << nav.failure();
  const auto clears = kinds(nav, "clear_global_costmap");
  ASSERT_FALSE(clears.empty());
  EXPECT_EQ(clears.front(), "ClearGlobalCostmap-Context");
  // The planner's retry after the context clear waits for the cleared costmap's next update (1 Hz): the first two
  // plans are a second apart, not at the same instant.
  std::vector<double> failed_s;
  for (const auto& e : nav.events())
    if (e.kind == "plan_failed") failed_s.push_back(e.time_s);
  ASSERT_GE(failed_s.size(), 2u);
  EXPECT_NEAR(failed_s[1] - failed_s[0], 1.0, 1e-6);
}

TEST(Navigator, ClearingResetsTheLayerThroughTheCallback) {
  mapping::Costmap2D blocked = room();
  for (int y = 0; y < 80; ++y) blocked.cells[y * 200 + 100] = mapping::kCostLethal;
  Navigator nav(config({8.0, 2.0, 0.0}), blocked);
  int local_resets = 0, global_resets = 0;
  nav.set_clear_layers([&](double) { ++local_resets; }, [&](double) { ++global_resets; });
  Drive d{nav, empty_layer(), {1.0, 2.0, 0.0}};
  d.run(2.5);
  EXPECT_GE(global_resets, 1);  // ClearGlobalCostmap-Context at the first failed plan
  // Each costmap's clearing resets its own layer: the planner's context clears the global one alone, the
  // recoveries' ClearingActions both (here: the context at 0 s, its retry failing at the cleared costmap's next
  // update at 1 s, the clearing recovery then).
  EXPECT_EQ(global_resets, static_cast<int>(kinds(nav, "clear_global_costmap").size()));
  EXPECT_EQ(local_resets, static_cast<int>(kinds(nav, "clear_local_costmap").size()));
  EXPECT_GT(global_resets, local_resets);
  EXPECT_GE(local_resets, 1);
}

TEST(Navigator, AStaleLayerMakesThePlannerAndControllerWaitThenTimeOut) {
  Navigator nav(config({8.0, 2.0, 0.0}), room());
  Drive d{nav, empty_layer(), {1.0, 2.0, 0.0}};
  d.run(1.0);  // current: planning and driving
  ASSERT_FALSE(nav.plans().empty());
  const double x_before = d.pose.x_m;
  EXPECT_GT(x_before, 1.05);
  // The layer goes stale: the local costmap (5 Hz) is not current from its next update; the controller keeps the
  // last command for costmap_update_timeout (0.3 s), then ControllerTimedOut. The global costmap (1 Hz) follows at
  // its next update and the planner times out 1.0 s later. A cleared costmap is current at its next update whatever
  // the layer says (was_reset_): the clear recovery's ClearGlobalCostmap lets one plan through.
  d.layer_current = false;
  d.run(6.0);
  double cleared_s = -1, planned_after_s = -1;
  for (const auto& e : nav.events()) {
    if (e.kind == "clear_global_costmap" && cleared_s < 0) cleared_s = e.time_s;
    if (e.kind == "plan" && cleared_s >= 0 && planned_after_s < 0) planned_after_s = e.time_s;
  }
  ASSERT_GE(cleared_s, 0.0);
  EXPECT_GT(planned_after_s, cleared_s);
  EXPECT_LE(planned_after_s, cleared_s + 1.0 + 1e-9) << "the global costmap's next update after the clear is current";
  const auto controller = kinds(nav, "controller_failed");
  ASSERT_FALSE(controller.empty());
  EXPECT_EQ(controller.front(), "ControllerTimedOut: Costmap timed out waiting for update");
  const auto planner = kinds(nav, "plan_failed");
  ASSERT_FALSE(planner.empty());
  EXPECT_EQ(planner.front(), "PlannerTimedOut: Costmap timed out waiting for update");
  EXPECT_GE(nav.recoveries(), 1);
}

TEST(Navigator, AnObstacleOnlyTheLayerSeesIsDrivenAround) {
  mapping::Costmap2D layer = room();  // the layer's grid in the world frame: a box in the middle of the way
  std::fill(layer.cells.begin(), layer.cells.end(), mapping::kCostFree);
  for (int y = 30; y < 50; ++y)
    for (int x = 90; x < 100; ++x) layer.cells[y * 200 + x] = mapping::kCostLethal;
  Navigator nav(config({8.0, 2.0, 0.0}), room());
  std::vector<PlanCycle> plans;
  nav.set_plan_observer([&](const PlanCycle& p, const NavCostmap&) { plans.push_back(p); });
  Drive d{nav, layer, {1.0, 2.0, 0.0}};
  double closest = INFINITY;
  while (nav.status() == NavigationStatus::kRunning && d.t < 60) {
    d.run(0.05);
    // distance from the robot's centre to the box [4.5, 5.0] x [1.5, 2.5]
    const double dx = std::max({4.5 - d.pose.x_m, 0.0, d.pose.x_m - 5.0});
    const double dy = std::max({1.5 - d.pose.y_m, 0.0, d.pose.y_m - 2.5});
    closest = std::min(closest, std::hypot(dx, dy));
  }
  ASSERT_EQ(nav.status(), NavigationStatus::kSucceeded) << nav.failure();
  EXPECT_GT(closest, 0.2);  // never touched it with its 0.2 m radius
  ASSERT_FALSE(plans.empty());
  EXPECT_TRUE(plans.front().found);
  EXPECT_GT(plans.front().length_m, 7.2);  // around the box, longer than the 7 m straight line
}

TEST(Navigator, GoalOffTheMapFailsWithoutRecoveries) {
  Navigator nav(config({30.0, 2.0, 0.0}), room());
  Drive d{nav, empty_layer(), {1.0, 2.0, 0.0}};
  d.run(5);
  ASSERT_EQ(nav.status(), NavigationStatus::kFailed);
  EXPECT_EQ(nav.recoveries(), 0);  // GoalOutsideMapBounds: WouldAPlannerRecoveryHelp is false
  EXPECT_NE(nav.failure().find("GoalOutsideMapBounds"), std::string::npos) << nav.failure();
}

TEST(Navigator, ConfigRefusesAnInflationRadiusInsideTheRobot) {
  NavigationConfig c = config({8, 2, 0});
  c.local_costmap.inflation.inflation_radius_m = 0.1;
  try {
    c.validate();
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("local_costmap.inflation_layer.inflation_radius"), std::string::npos);
  }
}

}  // namespace
}  // namespace stvl::navigation

#pragma once
// nav2 driving the robot from the costmaps: the default behaviour tree (nav2_bt_navigator
// navigate_to_pose_w_replanning_and_recovery.xml, navigation2 jazzy f4108e5) around planner_server (NavFn),
// controller_server (Regulated Pure Pursuit, the goal and progress checkers, failure_tolerance) and
// behavior_server (Spin, BackUp, Wait), on the local and global costmaps (costmaps.hpp).
//
//   RecoveryNode(number_of_retries 6)
//     PipelineSequence
//       RateController(1 Hz) RecoveryNode(1) ComputePathToPose | ClearGlobalCostmap-Context
//       RecoveryNode(1) FollowPath | ClearLocalCostmap-Context
//     Sequence(would a recovery help?, RoundRobin(clear both costmaps, Spin 1.57, Wait 5 s, BackUp 0.30 m))
//
// The tree is ticked at every controller cycle (controller_frequency) and the planner's and behaviours' work is
// instantaneous in simulated time: a plan is there at the tick that asked for it.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "navigation/behaviors.hpp"
#include "navigation/config.hpp"
#include "navigation/costmaps.hpp"

namespace stvl::navigation {

enum class NavigationStatus { kRunning, kSucceeded, kFailed };

// What the tree did, in time order. kinds: "plan", "plan_failed", "clear_global_costmap", "clear_local_costmap",
// "controller_failed", "recovery" (detail: clear, spin, wait, backup), "recovery_done", "recovery_failed",
// "goal_reached", "navigation_failed".
struct NavigationEvent {
  double time_s = 0;
  std::string kind, detail;
  Eigen::Vector2d at_W = Eigen::Vector2d::Zero();  // the robot then (its true pose, whatever the localizer said)
};

// One ComputePathToPose on the global costmap.
struct PlanCycle {
  double time_s = 0;
  Pose2 robot_W;
  bool found = false;
  std::vector<Eigen::Vector2d> path_W;
  double length_m = 0;
  std::string failure;  // why not, when !found
  // Whether a recovery could help (WouldAPlannerRecoveryHelp: NO_VALID_PATH); not for a start or goal off the
  // map or a goal in a lethal cell with tolerance 0 (StartOutsideMapBounds, GoalOutsideMapBounds, GoalOccupied).
  bool recovery_helps = true;
};

class Navigator {
 public:
  // static_map: the global costmap's static layer (its grid is the global costmap's). Throws
  // std::invalid_argument for a config that validate() refuses.
  Navigator(NavigationConfig config, mapping::Costmap2D static_map);

  // ClearEntireCostmap also resets the costmap's 3D layer (nav2 runs one instance per costmap): `local` is called
  // with the time at each ClearLocalCostmap, `global` at each ClearGlobalCostmap (either may be empty).
  void set_clear_layers(std::function<void(double time_s)> local, std::function<void(double time_s)> global) {
    clear_local_layer_ = std::move(local);
    clear_global_layer_ = std::move(global);
  }
  // Called after every ComputePathToPose with its result and the global costmap it planned on.
  void set_plan_observer(std::function<void(const PlanCycle&, const NavCostmap& global)> observer) {
    plan_observer_ = std::move(observer);
  }

  // The costmaps' clocks: each one due at time_s (of those asked for) takes the layer's current grid (world frame)
  // around the robot.
  // layer_current: the 3D layer's isCurrent then (a source past its expected_update_rate makes it false).
  void update_costmaps(double time_s, const mapping::Costmap2D& layer_W, const Pose2& robot_W, bool local = true,
                       bool global = true, bool layer_current = true);
  // One tick of the tree and the controller at time_s with the robot's pose and velocity: the twist to drive.
  // robot_map: with localization, the robot as the localizer has it in map (robot_W is then odometry's frame, the
  // local costmap's): the planner starts there, the plan (in map) is followed and the goal checked through it.
  Twist tick(double time_s, const Pose2& robot_W, const Twist& velocity,
             const std::optional<Pose2>& robot_map = std::nullopt);

  NavigationStatus status() const { return status_; }
  const std::string& failure() const { return failure_; }  // why the navigation failed
  double finished_at_s() const { return finished_at_s_; }
  const std::vector<NavigationEvent>& events() const { return events_; }
  const std::vector<PlanCycle>& plans() const { return plans_; }
  int recoveries() const { return recoveries_; }  // recoveries that ran (round robin actions started)
  const NavCostmap& local_costmap() const { return local_; }
  const NavCostmap& global_costmap() const { return global_; }
  const NavigationConfig& config() const { return config_; }
  // The behaviour running now, if any.
  std::optional<BehaviorKind> behavior_running() const;

 private:
  enum class Stage { kPipeline, kRecovery, kDone };
  // ComputePathToPose from `localized` (the planner's start) with its context recovery: false when the pipeline fails
  // (the retry after the context clear is pending until the cleared costmap is current). Events are at `robot`.
  bool plan(double time_s, const Pose2& robot, const Pose2& localized);
  PlanCycle compute_path(double time_s, const Pose2& robot);
  void clear_global(double time_s, const Pose2& robot, const std::string& why);
  void clear_local(double time_s, const Pose2& robot, const std::string& why);
  void restart_follow();
  void restart_pipeline();
  // The pipeline failed: a recovery from the round robin, or the end.
  Twist pipeline_failed(double time_s, const Pose2& robot, const std::string& why, bool recovery_helps);
  // FollowPath failed: its RecoveryNode's ClearLocalCostmap-Context once, then the pipeline fails.
  Twist controller_failed(double time_s, const Pose2& robot, const std::string& why);
  Twist start_recovery(double time_s, const Pose2& robot);
  void finish(double time_s, NavigationStatus status, const std::string& why, const Pose2& robot);
  void event(double time_s, const Pose2& robot, std::string kind, std::string detail = {});

  NavigationConfig config_;
  NavCostmap local_, global_;
  std::vector<Eigen::Vector2d> footprint_m_;
  RegulatedPurePursuit controller_;
  SimpleGoalChecker goal_checker_;
  SimpleProgressChecker progress_checker_;
  Behavior behavior_;
  std::function<void(double)> clear_local_layer_, clear_global_layer_;
  std::optional<double> plan_waiting_since_s_, controller_waiting_since_s_;  // waiting for a current costmap
  Twist last_twist_;  // the controller's last command (the base keeps it while nothing is published)
  std::function<void(const PlanCycle&, const NavCostmap&)> plan_observer_;

  Stage stage_ = Stage::kPipeline;
  NavigationStatus status_ = NavigationStatus::kRunning;
  std::string failure_;
  double finished_at_s_ = 0;
  double next_plan_s_ = 0;
  bool plan_now_ = true, have_path_ = false;
  bool planner_context_used_ = false, controller_context_used_ = false;
  std::optional<double> last_valid_s_;  // controller_server's last_valid_cmd_time_ (failure_tolerance)
  int retries_ = 0, recoveries_ = 0;
  int round_robin_ = 0, round_robin_failed_ = 0;
  std::vector<NavigationEvent> events_;
  std::vector<PlanCycle> plans_;
};

}  // namespace stvl::navigation

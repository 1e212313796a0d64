#include "navigation/navigator.hpp"

#include <cmath>

#include "navigation/footprint.hpp"

namespace stvl::navigation {
namespace {

std::string fixed2(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f", v);
  return text;
}

}  // namespace

Navigator::Navigator(NavigationConfig config, mapping::Costmap2D static_map)
    : config_((config.validate(), std::move(config))),
      local_(config_.local_costmap, config_.inscribed_radius_m()),
      global_(config_.global_costmap, config_.inscribed_radius_m(), std::move(static_map)),
      footprint_m_(config_.footprint_polygon_m()),
      controller_(config_.controller,
                  LocalCostmapConfig{config_.footprint_m, config_.robot_radius_m, config_.footprint_padding_m,
                                     config_.local_costmap.track_unknown_space}),
      goal_checker_(config_.goal_checker),
      progress_checker_(config_.progress_checker),
      behavior_(config_.behaviors, [this](const Pose2& pose) {
        // CostmapTopicCollisionChecker::isCollisionFree on the local costmap: off the grid is a collision.
        const mapping::Costmap2D& m = local_.costmap();
        int mx, my;
        if (!world_to_cell(m, pose.x_m, pose.y_m, mx, my)) return false;
        return footprint_cost(m, place_footprint(footprint_m_, pose.x_m, pose.y_m, pose.yaw_rad)) <
               mapping::kCostLethal;
      }) {}

std::optional<BehaviorKind> Navigator::behavior_running() const {
  if (stage_ == Stage::kRecovery) return behavior_.kind();
  return std::nullopt;
}

void Navigator::update_costmaps(double time_s, const mapping::Costmap2D& layer_W, const Pose2& robot_W, bool local,
                                bool global, bool layer_current) {
  const Eigen::Vector2d robot(robot_W.x_m, robot_W.y_m);
  if (local && local_.due(time_s)) local_.update(time_s, layer_W, robot, layer_current);
  if (global && global_.due(time_s)) global_.update(time_s, layer_W, robot, layer_current);
}

void Navigator::event(double time_s, const Pose2& robot, std::string kind, std::string detail) {
  events_.push_back({time_s, std::move(kind), std::move(detail), Eigen::Vector2d(robot.x_m, robot.y_m)});
}

void Navigator::finish(double time_s, NavigationStatus status, const std::string& why, const Pose2& robot) {
  stage_ = Stage::kDone;
  status_ = status;
  failure_ = why;
  finished_at_s_ = time_s;
  event(time_s, robot, status == NavigationStatus::kSucceeded ? "goal_reached" : "navigation_failed", why);
}

void Navigator::clear_global(double time_s, const Pose2& robot, const std::string& why) {
  event(time_s, robot, "clear_global_costmap", why);
  if (clear_global_layer_) clear_global_layer_(time_s);
  global_.clear();
}

void Navigator::clear_local(double time_s, const Pose2& robot, const std::string& why) {
  event(time_s, robot, "clear_local_costmap", why);
  if (clear_local_layer_) clear_local_layer_(time_s);
  local_.clear();
}

PlanCycle Navigator::compute_path(double time_s, const Pose2& robot) {
  PlanCycle cycle;
  cycle.time_s = time_s;
  cycle.robot_W = robot;
  const PlanResult result =
      navfn_plan(global_.costmap(), {robot.x_m, robot.y_m}, {config_.goal.x_m, config_.goal.y_m}, config_.planner);
  // WouldAPlannerRecoveryHelp: only NO_VALID_PATH (StartOutsideMapBounds, GoalOutsideMapBounds, GoalOccupied: no).
  cycle.recovery_helps = result.found || result.failure_kind == PlanFailure::kNoValidPath;
  cycle.found = result.found;
  cycle.path_W = result.path_W;
  cycle.length_m = path_length_m(result.path_W);
  cycle.failure = result.failure;
  plans_.push_back(cycle);
  if (plan_observer_) plan_observer_(cycle, global_);
  return cycle;
}

void Navigator::restart_follow() {
  controller_.reset();
  progress_checker_.reset();
  goal_checker_.reset();
  last_valid_s_.reset();
}

// A recovery succeeded: the outer RecoveryNode counts a retry and ticks the pipeline again, whose nodes were halted
// (the inner RecoveryNodes' retries and the RateController start over: a plan at once).
void Navigator::restart_pipeline() {
  ++retries_;
  stage_ = Stage::kPipeline;
  plan_now_ = true;
  have_path_ = false;
  planner_context_used_ = controller_context_used_ = false;
  // The halted ComputePathToPose and FollowPath goals are gone: the new ones wait for their costmap anew
  // (waitForCostmap's timer starts with the goal).
  plan_waiting_since_s_.reset();
  controller_waiting_since_s_.reset();
  restart_follow();
}

bool Navigator::plan(double time_s, const Pose2& robot, const Pose2& localized) {
  next_plan_s_ = time_s + 1.0 / config_.replan_frequency_hz;
  plan_now_ = false;
  PlanCycle cycle = compute_path(time_s, localized);
  if (!cycle.found) {
    event(time_s, robot, "plan_failed", cycle.failure);
    // RecoveryNode(1) ComputePathToPose | ClearGlobalCostmap-Context: once, then the planner again, which waits
    // for the cleared costmap's next update (planner_server::waitForCostmap: "after clear costmap"); the controller
    // goes on with the path it has meanwhile (the PipelineSequence's planner branch is running).
    if (planner_context_used_ || !cycle.recovery_helps) return false;
    planner_context_used_ = true;
    clear_global(time_s, robot, "ClearGlobalCostmap-Context");
    plan_now_ = true;
    return true;
  }
  planner_context_used_ = false;  // a success resets the RecoveryNode
  std::vector<Pose2> poses;
  for (const auto& p : cycle.path_W) poses.push_back({p.x(), p.y(), 0.0});
  if (!poses.empty()) poses.back().yaw_rad = config_.goal.yaw_rad;  // NavFn: the last pose takes the goal's
  controller_.set_plan(poses);
  goal_checker_.reset();  // controller_server::setPlannerPath
  have_path_ = true;
  event(time_s, robot, "plan", fixed2(cycle.length_m) + " m");
  return true;
}

Twist Navigator::tick(double time_s, const Pose2& robot, const Twist& velocity, const std::optional<Pose2>& robot_map) {
  if (stage_ == Stage::kDone) return {};
  const Pose2& localized = robot_map.value_or(robot);  // the robot in map: the planner's start, the goal check's
  if (stage_ == Stage::kRecovery) {
    const BehaviorStatus s = behavior_.update(time_s, robot);
    if (s == BehaviorStatus::kRunning) return behavior_.twist();
    if (s == BehaviorStatus::kFailed) {
      event(time_s, robot, "recovery_failed", std::string(to_string(behavior_.kind())) + ": " + behavior_.failure());
      ++round_robin_failed_;
      return start_recovery(time_s, robot);
    }
    event(time_s, robot, "recovery_done", to_string(behavior_.kind()));
    round_robin_failed_ = 0;
    restart_pipeline();
  }
  // PipelineSequence: the planner at its rate, then FollowPath. planner_server::waitForCostmap: no plan until the
  // global costmap is current, PlannerTimedOut after costmap_update_timeout (the controller follows the old path
  // meanwhile: the planner's action is running).
  if (plan_now_ || time_s + 1e-9 >= next_plan_s_ || plan_waiting_since_s_) {
    if (!global_.current()) {
      if (!plan_waiting_since_s_) plan_waiting_since_s_ = time_s;
      if (time_s - *plan_waiting_since_s_ > config_.planner_costmap_timeout_s) {
        plan_waiting_since_s_.reset();
        next_plan_s_ = time_s + 1.0 / config_.replan_frequency_hz;
        plan_now_ = false;
        event(time_s, robot, "plan_failed", "PlannerTimedOut: Costmap timed out waiting for update");
        return pipeline_failed(time_s, robot, "no plan: the global costmap timed out waiting for update", true);
      }
    } else {
      plan_waiting_since_s_.reset();
      if (!plan(time_s, robot, localized))
        return pipeline_failed(time_s, robot, "no plan: " + plans_.back().failure, plans_.back().recovery_helps);
    }
  }
  if (!have_path_) return {};
  // controller_server::computeControl: no command until the local costmap is current; ControllerTimedOut after
  // costmap_update_timeout. Nothing is published meanwhile: the base keeps the last command.
  if (!local_.current()) {
    if (!controller_waiting_since_s_) controller_waiting_since_s_ = time_s;
    if (time_s - *controller_waiting_since_s_ <= config_.controller_costmap_timeout_s) return last_twist_;
    controller_waiting_since_s_.reset();
    return controller_failed(time_s, robot, "ControllerTimedOut: Costmap timed out waiting for update");
  }
  controller_waiting_since_s_.reset();
  // controller_server::computeControl: the goal check, then computeAndPublishVelocity (the progress check, then the
  // controller); the odometry's speeds under min_*_velocity_threshold (0.0001) read as zero.
  const auto thresholded = [](double v) { return std::abs(v) < 0.0001 ? 0.0 : v; };
  const Twist speed{thresholded(velocity.v_mps), thresholded(velocity.omega_radps)};
  if (goal_checker_.is_goal_reached(localized, config_.goal, speed)) {
    finish(time_s, NavigationStatus::kSucceeded, "", robot);
    return {};
  }
  std::string controller_failure;
  Twist twist;
  if (!progress_checker_.check(robot, time_s)) {
    controller_failure = "failed to make progress";
  } else {
    const RppCommand command =
        controller_.compute(robot, speed, local_.costmap(), 1.0 / config_.controller_frequency_hz,
                            goal_checker_.xy_goal_tolerance_m(), robot_map);
    if (!last_valid_s_) last_valid_s_ = time_s;  // computeControl: last_valid_cmd_time_ = now at the start
    if (command.status == RppStatus::kOk) {
      last_valid_s_ = time_s;
      twist = command.twist;
    } else if (command.status == RppStatus::kCollisionAhead &&
               (config_.failure_tolerance_s > 0 || config_.failure_tolerance_s == -1.0)) {
      // controller_server: NoValidControl tolerated with zero velocity until failure_tolerance since the last valid
      // command (PatienceExceeded); -1 never gives up.
      if (config_.failure_tolerance_s != -1.0 && time_s - *last_valid_s_ > config_.failure_tolerance_s)
        controller_failure = "controller patience exceeded (" + command.message + ")";
      twist = {};
    } else {
      controller_failure = command.message;  // any other exception aborts FollowPath at once
    }
  }
  if (controller_failure.empty()) return last_twist_ = twist;
  return controller_failed(time_s, robot, controller_failure);
}

Twist Navigator::controller_failed(double time_s, const Pose2& robot, const std::string& controller_failure) {
  last_twist_ = {};
  event(time_s, robot, "controller_failed", controller_failure);
  // RecoveryNode(1) FollowPath | ClearLocalCostmap-Context.
  if (!controller_context_used_) {
    controller_context_used_ = true;
    clear_local(time_s, robot, "ClearLocalCostmap-Context");
    restart_follow();
    return {};
  }
  return pipeline_failed(time_s, robot, controller_failure, true);
}

Twist Navigator::pipeline_failed(double time_s, const Pose2& robot, const std::string& why, bool recovery_helps) {
  have_path_ = false;
  if (!recovery_helps) {
    finish(time_s, NavigationStatus::kFailed, why, robot);
    return {};
  }
  if (retries_ >= config_.number_of_retries) {
    finish(time_s, NavigationStatus::kFailed,
           why + " after " + std::to_string(retries_) + " recoveries (number_of_retries)", robot);
    return {};
  }
  round_robin_failed_ = 0;
  return start_recovery(time_s, robot);
}

// RoundRobin(ClearingActions, Spin, Wait, BackUp): the next child; a failure moves on to the next, all four failing
// in a row fail the recovery and so the navigation.
Twist Navigator::start_recovery(double time_s, const Pose2& robot) {
  stage_ = Stage::kRecovery;
  last_twist_ = {};
  while (round_robin_failed_ < 4) {
    const int child = round_robin_;
    round_robin_ = (round_robin_ + 1) % 4;
    ++recoveries_;
    if (child == 0) {  // ClearingActions: local then global, both succeed at once
      event(time_s, robot, "recovery", "clear");
      clear_local(time_s, robot, "ClearLocalCostmap-Subtree");
      clear_global(time_s, robot, "ClearGlobalCostmap-Subtree");
      event(time_s, robot, "recovery_done", "clear");
      restart_pipeline();
      return {};
    }
    const BehaviorKind kind = child == 1   ? BehaviorKind::kSpin
                              : child == 2 ? BehaviorKind::kWait
                                           : BehaviorKind::kBackUp;
    event(time_s, robot, "recovery", to_string(kind));
    behavior_.start(kind, time_s, robot);
    const BehaviorStatus s = behavior_.update(time_s, robot);
    if (s == BehaviorStatus::kRunning) return behavior_.twist();
    if (s == BehaviorStatus::kSucceeded) {  // done at once (nothing left to turn or drive)
      event(time_s, robot, "recovery_done", to_string(kind));
      restart_pipeline();
      return {};
    }
    event(time_s, robot, "recovery_failed", std::string(to_string(kind)) + ": " + behavior_.failure());
    ++round_robin_failed_;
  }
  finish(time_s, NavigationStatus::kFailed, "every recovery failed", robot);
  return {};
}

}  // namespace stvl::navigation

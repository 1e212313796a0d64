#pragma once
// What a closed-loop drive cost, measured against the truth (issue 41): success, time to goal, path length, SPL,
// collisions, clearance, stalls, replans, recoveries; and at every planning cycle the attribution: NavFn run again
// on a costmap built from the truth (the static map plus every true footprint cell now, the same inflation), so a
// plan the layer's costmap lacks or makes >= 1.5x longer is "blocked by phantoms" (its lethal cells where the truth
// is free, near the truth's plan, named), and a plan that crosses true lethal cells is "driving into the unseen".
#include <string>
#include <vector>

#include <Eigen/Core>

#include "evaluation/checks.hpp"
#include "evaluation/truth.hpp"
#include "mapping/costmap.hpp"
#include "navigation/navigator.hpp"
#include "sim/world.hpp"

namespace stvl::evaluation {

// The static map a mapping run would have left: the footprints (cells of resolution_m, solids met in
// [min_z_m, max_z_m]) of the obstacle bodies whose names start with one of `prefixes` lethal, every other cell of
// extent_W (grown to whole cells from multiples of resolution_m) free. People, carts and boxes are never in it.
mapping::Costmap2D building_map(const sim::World& world, const std::vector<std::string>& prefixes, double resolution_m,
                                double min_z_m, double max_z_m, const Eigen::AlignedBox2d& extent_W);

struct DriveCollision {
  double time_s = 0;
  std::string body;  // what the robot touched (physics contacts; "obstacle" for the kinematic drive's overlap)
  Eigen::Vector2d at_W = Eigen::Vector2d::Zero();
};
struct DriveStall {
  double from_s = 0, to_s = 0;
  Eigen::Vector2d at_W = Eigen::Vector2d::Zero();
};
// One planning cycle judged against the truth.
struct PlanAttribution {
  double time_s = 0;
  bool layer_found = false, truth_found = false;
  double layer_length_m = 0, truth_length_m = 0;
  bool blocked_by_phantoms = false;  // truth has a plan; the layer none, or one >= 1.5x longer
  bool into_unseen = false;          // the layer's plan crosses true lethal cells
  std::size_t phantom_cells = 0;     // blocking: the layer's lethal cells where the truth is free near the truth's plan
  std::size_t unseen_cells = 0;      // the true lethal cells the layer's plan crosses
  std::vector<Eigen::Vector2d> phantom_cells_W, unseen_cells_W;  // their centres, the first kListed
  // How far the pose the planner started from (the localizer's, in map) lay from the truth: the global costmap's
  // readings were placed with an error of this order (0 without localization).
  double localization_error_m = 0;
};

struct DriveSummary {
  bool evaluated = false;  // navigation.mode closed_loop
  bool success = false;    // the goal checker passed before the run's end
  std::string outcome;     // "goal reached", or the diagnosis of a failure
  // SPL = success x shortest / max(driven, shortest); the shortest path runs through the truth's cells below
  // inscribed (8-connected) from the start to the goal at the first planning cycle (the static map's cells when a
  // moving body shuts the way then).
  double time_to_goal_s = 0, path_length_m = 0, shortest_truth_m = 0, spl = 0;
  std::vector<DriveCollision> collisions;
  double min_clearance_m = 0;  // footprint to the nearest true obstacle cell, over the drive
  double stalled_s = 0;        // moving under 0.02 m/s for 1 s and more while navigating
  std::vector<DriveStall> stalls;
  std::size_t plans = 0, plan_failures = 0, recoveries = 0;
  std::vector<navigation::NavigationEvent> events;
  std::vector<PlanAttribution> attributions;
  double blocked_time_s = 0;  // planning cycles blocked by phantoms, each counted to the next cycle
  std::size_t blocked_cycles = 0, unseen_cycles = 0;
  struct Sample {
    double time_s, x_m, y_m, yaw_rad, v_mps, omega_radps;
  };
  std::vector<Sample> trajectory;               // per frame
  std::vector<navigation::PlanCycle> plan_log;  // every plan (the report draws every few)
  // Wall-clock milliseconds over the run (profiling only): nav2's side (the tree, planner, controller, costmaps) and
  // the judging (the truth's costmap and plan at each cycle, clearance, contacts).
  double navigation_ms = 0, attribution_ms = 0;
};

// navigation_success, collisions, time_to_goal, recoveries, blocked_time: one result per threshold set, in that
// order; a failure's message carries the drive's diagnosis (DriveSummary::outcome).
// cut_short: --duration ended the run before the scenario's own duration; navigation_success and time_to_goal are
// then not evaluated when the goal was not reached, unless required (run --require-path), as path_completed.
std::vector<CheckResult> drive_checks(const ChecksConfig& checks, const DriveSummary& drive, bool cut_short = false,
                                      bool required_when_cut_short = false);

class DriveEvaluation {
 public:
  static constexpr std::size_t kListed = 20;
  // truth_cell_m: the truth's footprint cells (the evaluation's voxel size); geometric_collisions: the kinematic drive,
  // whose robot touches nothing in the physics (the footprint overlapping a true cell counts instead).
  DriveEvaluation(const navigation::NavigationConfig& config, mapping::Costmap2D building, double truth_cell_m,
                  bool geometric_collisions);
  // Each frame: trajectory, clearance against truth.footprint() now, collisions (contacts names; empty with the
  // kinematic drive: the footprint overlapping a true cell counts), stalls.
  void frame(double time_s, const navigation::Pose2& robot_W, const navigation::Twist& command, const Truth& truth,
             const std::vector<std::string>& contacts, bool navigating);
  // Each planning cycle: the truth's costmap and plan (from robot_W, the true pose) beside the layer's (from the
  // pose the planner had: the localizer's with localization).
  void plan_cycle(const navigation::PlanCycle& cycle, const navigation::NavCostmap& global, const Truth& truth,
                  const navigation::Pose2& robot_W);
  DriveSummary finish(const navigation::Navigator& navigator, double end_s);
  // The global costmap built from the truth now: the static map with every true footprint cell lethal (combined),
  // and with the global costmap's inflation.
  mapping::Costmap2D truth_costmap(const Truth& truth) const;
  mapping::Costmap2D truth_inflated(const Truth& truth) const;

 private:
  navigation::NavigationConfig config_;
  mapping::Costmap2D building_;
  std::vector<Eigen::Vector2d> footprint_m_;
  DriveSummary s_;
  double last_time_s_ = -1;
  Eigen::Vector2d last_p_ = Eigen::Vector2d::Zero();
  double slow_since_s_ = -1;
  std::vector<std::string> touching_;
  bool overlapping_ = false;
  double truth_cell_m_;
  bool geometric_collisions_;
  double first_plan_s_ = -1;
};

}  // namespace stvl::evaluation

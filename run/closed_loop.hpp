#pragma once
// navigation.mode closed_loop in a run (issue 41): nav2 (navigation/) drives the simulated robot from the layer's
// costmaps, and the drive is judged against the truth (evaluation/drive.hpp).
//
//   sim step (every 1 / controller_frequency) -> the costmaps due (their clocks) -> Navigator::tick -> wheels
//   frame loop, after the layer's update      -> the global costmap's own layer -> DriveEvaluation::frame
//   every ComputePathToPose                    -> DriveEvaluation::plan_cycle (the truth's plan beside it)
#include <memory>
#include <optional>
#include <string>

#include "config/scenario.hpp"
#include "evaluation/drive.hpp"
#include "evaluation/run_evaluation.hpp"
#include "layer/layer.hpp"
#include "navigation/navigator.hpp"
#include "pipeline/pipeline.hpp"
#include "run/bag_recorder.hpp"

namespace stvl::run {

class ClosedLoop {
 public:
  // Builds the static map from the world's building (navigation.static_bodies), checks the goal against the truth
  // now and hands the robot's wheels to the navigator. Throws std::invalid_argument (exit 2) for a goal outside the
  // map, in or too near an obstacle, or unreachable in the truth, naming the nearest free cell.
  // bag: the run writes one (the controller's twists are kept for it).
  ClosedLoop(const config::Scenario& scenario, pipeline::Pipeline& pipeline, layer::Layer& layer,
             const evaluation::RunEvaluation& evaluation, bool bag);
  // After each frame's layer update: the global costmap's own layer takes the frame's observation; the drive's
  // figures. (The costmaps update on their own clocks at the controller's ticks, frames or not, as nav2's timers.)
  void after_frame(const pipeline::Frame& frame);
  // A frame lost on the way at time_s (camera timing): the drive is judged as at a frame (trajectory, clearance,
  // collisions, stalls), so a robot driving blind is still watched.
  void after_lost_frame(double time_s) { judge(time_s); }
  // Before the frame at time_s goes into the bag: the twists, plans and costmaps published since the last frame.
  void record_bag(BagRecorder& bag, double time_s);
  // Whether the navigation ended (the goal reached or given up).
  bool finished() const { return navigator_->status() != navigation::NavigationStatus::kRunning; }
  // The drive's figures at the run's end (end_s).
  evaluation::DriveSummary finish(double end_s);
  const navigation::Navigator& navigator() const { return *navigator_; }

 private:
  navigation::Pose2 robot_pose() const;
  // The drive's figures at time_s against the truth now.
  void judge(double time_s);
  // With localization: the robot in map as the localizer has it (the last correction composed with odometry).
  std::optional<navigation::Pose2> localized_pose() const;
  // The costmaps due at time_s take their layers' grids as the last update left them.
  void update_costmaps(double time_s);

  const config::Scenario& s_;
  pipeline::Pipeline& pipeline_;
  layer::Layer& layer_;  // the local costmap's (the run's layer: its map is the one scored)
  // The global costmap's own instance (nav2 runs one per costmap), fed the same observations; null where the
  // local one serves both (nav2's layers: their window is the local costmap's).
  std::unique_ptr<layer::Layer> global_layer_;
  layer::UpdateReport global_report_;
  const evaluation::RunEvaluation& evaluation_;
  std::unique_ptr<navigation::Navigator> navigator_;
  std::unique_ptr<evaluation::DriveEvaluation> drive_;
  bool bag_;
  std::vector<std::pair<double, Eigen::Vector2d>> twists_;  // the controller's ticks since the last bag frame
  std::size_t plans_written_ = 0;
  double next_local_publish_s_ = 0, next_global_publish_s_ = 0;
  double navigation_ms_ = 0, attribution_ms_ = 0;  // wall clock: nav2's side, the truth's side
};

}  // namespace stvl::run

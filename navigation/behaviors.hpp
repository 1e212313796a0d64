#pragma once
// nav2's recovery behaviours as the default tree calls them (nav2_behaviors, navigation2 jazzy f4108e5): Spin
// (plugins/spin.cpp), BackUp (DriveOnHeading with a negative distance and speed, drive_on_heading.hpp) and Wait
// (plugins/wait.cpp). Each runs at behavior_server's cycle_frequency; Spin and BackUp check the local costmap
// ahead (CostmapTopicCollisionChecker::isCollisionFree: the footprint's cost below lethal, on the grid).
#include <functional>
#include <string>

#include "navigation/config.hpp"

namespace stvl::navigation {

enum class BehaviorKind { kSpin, kBackUp, kWait };
const char* to_string(BehaviorKind kind);  // "spin", "backup", "wait"

enum class BehaviorStatus { kRunning, kSucceeded, kFailed };

class Behavior {
 public:
  // collision_free(pose): whether the robot's footprint at pose (odom = world here) is free on the local costmap.
  using CollisionFree = std::function<bool(const Pose2& pose)>;
  Behavior(const BehaviorParams& params, CollisionFree collision_free);

  // onRun: the behaviour starts at time_s from pose.
  void start(BehaviorKind kind, double time_s, const Pose2& pose);
  // One call per controller tick: onCycleUpdate at the behaviour's cycle (the twist held between cycles). Returns
  // the status; twist() is what to drive (zero once it ended).
  BehaviorStatus update(double time_s, const Pose2& pose);
  const Twist& twist() const { return twist_; }
  BehaviorKind kind() const { return kind_; }
  // Why it failed ("collision ahead", "time allowance exceeded"); empty otherwise.
  const std::string& failure() const { return failure_; }

 private:
  BehaviorStatus cycle(double time_s, const Pose2& pose);
  bool spin_collision_free(double relative_yaw, double omega, Pose2 pose) const;
  bool backup_collision_free(double distance, double v, Pose2 pose) const;

  BehaviorParams params_;
  CollisionFree collision_free_;
  BehaviorKind kind_ = BehaviorKind::kWait;
  double start_s_ = 0, next_cycle_s_ = 0;
  Pose2 initial_;
  double prev_yaw_ = 0, relative_yaw_ = 0;
  Twist twist_;
  BehaviorStatus status_ = BehaviorStatus::kSucceeded;
  std::string failure_;
};

}  // namespace stvl::navigation

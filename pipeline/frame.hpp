#pragma once
// One camera frame as the pipeline gives it: the robot's poses, the depth images, the cloud, and the observation
// the layer takes (decimated and banded clouds with the optical frame's pose and the stamp), with where every
// camera stands at that moment. Simulated frames (pipeline.hpp) and recorded ones (the replay) alike.
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "layer/observation.hpp"
#include "sensors/depth_image.hpp"

namespace stvl::sim {
class World;
}

namespace stvl::pipeline {

// Wall-clock milliseconds of one frame's sensing (the only part of a frame that is not deterministic). cloud_ms
// holds the camera's edge filter when it is enabled, depth to cloud, the transform to the world and the no-return
// rays. With several cameras at one instant the others draw ahead on their own threads (pipeline.hpp): their
// render_ms is the wait for that draw, and the drawing threads' time shows up in the stages the main thread ran
// meanwhile.
struct SensingTimes {
  double render_ms = 0, noise_ms = 0, cloud_ms = 0, filter_ms = 0;
};

// One odometry message as tf has it (issue 43): its stamp, the robot (truth), odometry, map -> odom then.
struct OdomMessage {
  double stamp_s = 0;
  Eigen::Isometry3d T_world_base = Eigen::Isometry3d::Identity(), T_odom_base = Eigen::Isometry3d::Identity(),
                    T_map_odom = Eigen::Isometry3d::Identity();
  double v_mps = 0, omega_radps = 0;
};

struct Frame {
  std::size_t camera_index = 0;
  std::string camera;
  std::size_t frame_index = 0;  // of this camera
  double time_s = 0;            // simulated (or recorded)
  double stamp_s = 0;           // the header stamp its driver wrote (time_s, but with camera timing; issue 43)
  // With camera timing: the odometry messages that reached tf since the previous frame (the bag's /tf, /odom and
  // ground truth at their stamps, so a replay finds the pose at any frame's stamp); tf_from_messages set.
  bool tf_from_messages = false;
  std::vector<OdomMessage> odom_messages;
  // False when the robot fell over or left the world at time_s: nothing below the poses was computed, and the run
  // should stop.
  bool robot_upright = true;
  // The simulated world at time_s (poses, contacts) for the evaluation against the truth: the pipeline's live world,
  // or its snapshot when the pipeline runs ahead (Pipeline::set_world_snapshots). Null for a recording.
  const sim::World* world = nullptr;
  bool path_finished = false;  // the robot had reached its path's end (Simulator::path_finished)
  int laps_completed = 0;      // Simulator::laps_completed
  // Per camera: frames skipped in its outages up to this one (Pipeline::skipped_frames just after it was taken).
  std::vector<std::size_t> skipped_frames;
  Eigen::Isometry3d T_world_base = Eigen::Isometry3d::Identity();    // truth
  Eigen::Isometry3d T_odom_base = Eigen::Isometry3d::Identity();     // wheel odometry
  Eigen::Isometry3d T_map_odom = Eigen::Isometry3d::Identity();      // odometry drift (map = world)
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();  // optical frame
  double odom_v_mps = 0, odom_omega_radps = 0;
  sensors::DepthImage clean_depth;  // rendered, noise-free (empty for a recording)
  sensors::DepthImage depth;        // with the camera's noise model (what the camera publishes)
  // With the camera's edge filter enabled: `depth` without the pixels it dropped (the image the cloud comes
  // from; pixels it dropped are not "no return" pixels); empty otherwise.
  sensors::DepthImage edge_filtered_depth;
  std::size_t edge_dropped_pixels = 0;
  // Valid pixels in the optical frame, row-major pixel order: the first point_count columns of points_C.
  Eigen::Matrix3Xf points_C;
  Eigen::Index point_count = 0;
  auto cloud_C() const { return points_C.leftCols(point_count); }  // the valid points (a view of points_C)
  Eigen::Matrix3Xf cloud_W;                                        // the same points in the world frame
  // What the layer takes (a new one per frame: the layer's buffers keep it): time_s, the poses, the decimated
  // cloud (clears), the marking cloud (decimated and inside the passthrough band), marking_B, no_return_W.
  std::shared_ptr<layer::Observation> observation;
  // Closed loop with localization: the same reading placed with the localizer's pose in map, for the global
  // costmap's layer (`observation` is then the local costmap's, in odom); null otherwise.
  std::shared_ptr<layer::Observation> observation_map;
  // Every camera at this frame (one per camera): its optical frame now and the time of its next frame.
  std::vector<layer::SensorNow> cameras_now;
  SensingTimes times;
};

}  // namespace stvl::pipeline

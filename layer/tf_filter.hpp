#pragma once
// tf as a robot has it, and the message filter every reading of STVL's and nav2's layers passes (issue 43).
// odom -> base_link is published at odom_rate_hz (stamps k / rate) and each message reaches the tf buffer
// odom_latency_s later; tf2 interpolates between the messages around a stamp, so a lookup at stamp s succeeds once
// the first message stamped at or after s has arrived. A reading (its stamp, its arrival) waits in
// tf2_ros::MessageFilter until its transform can be looked up, at most transform_tolerance after its arrival; then
// it is dropped (ROS 2's filter logs it "for reason 'Unknown'", STVL #216). Queue size and timeout as both layers
// construct the filter: MessageFilter(sub, tf, global_frame, 50, ..., durationFromSec(transform_tolerance)) in
// spatio_temporal_voxel_layer.cpp (ros2 branch, 0559ae8) and nav2_costmap_2d/plugins/obstacle_layer.cpp (jazzy
// f4108e5, lines 272-276).
#include <cstddef>
#include <string>

namespace stvl::layer {

// YAML tf (the robot's transforms) and the layer's transform_tolerance.
struct TfTimingConfig {
  double odom_rate_hz = 50.0;          // tf.odom_rate_hz
  double odom_latency_s = 0.0;         // tf.odom_latency_s
  double transform_tolerance_s = 0.2;  // the layer's transform_tolerance (STVL's default 0.2 s)
  std::size_t queue_size = 50;         // the message filter's queue (both layers: 50)
  // Throws std::invalid_argument naming the key for a rate <= 0, a negative latency or tolerance, NaN.
  void validate() const;
};

// When a lookup at stamp_s first succeeds: the first odom message stamped at or after it, plus its latency.
// Stamps before the first message (t < 0) can never be looked up: infinity.
double transform_available_s(const TfTimingConfig& config, double stamp_s);

enum class DropReason { kNone, kCamera, kTfTimeout, kQueueFull };
const char* to_string(DropReason reason);  // "delivered", "camera", "tf_timeout", "queue_full"

// The message filter's verdict on one reading: delivered at delivered_s (its arrival, or later when it waited for
// its transform), or dropped (kTfTimeout: the transform came later than arrival + transform_tolerance).
struct FilterVerdict {
  DropReason reason = DropReason::kNone;
  double delivered_s = 0;
  bool delivered() const { return reason == DropReason::kNone; }
};
FilterVerdict message_filter(const TfTimingConfig& config, double arrival_s, double stamp_s);

}  // namespace stvl::layer

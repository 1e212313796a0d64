#pragma once
// Recorded depth as frames for the pipeline: ROS 1 bags (realsense-ros's and librealsense's layouts) and folders
// of 16-bit depth PNGs, each frame with its intrinsics, its time and, where the recording has one, the pose of
// its optical frame. No ROS headers here: rosbag lives behind this interface (bag_reader.cpp).
//
//   auto recording = stvl::recording::open_recording("run.bag", options);   // throws on bad input
//   stvl::recording::RecordedFrame frame;
//   while (recording->next(frame)) { ... frame.depth, frame.intrinsics, frame.T_fixed_camera ... }
//
// Frames stream (a recording may not fit in memory); the poses are read before the first frame.
// Every reader throws std::invalid_argument with a message naming the file (and topic, frame or field) for bad
// input: a truncated or unreadable bag, no depth topic, an encoding that is not depth, a size that disagrees with
// the camera info, a step smaller than width x pixel size, zero or non-finite intrinsics, an empty or mixed PNG
// folder, a pose that is not a rigid transform.
#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sensors/camera.hpp"
#include "sensors/depth_image.hpp"

namespace stvl::recording {

struct RecordingOptions {
  // Bags: topics and frames; empty = found automatically (realsense-ros: /camera/depth/image_rect_raw or an
  // aligned-depth topic; librealsense: /device_0/sensor_N/Depth_0/image/data; the camera_info beside it).
  std::string depth_topic, info_topic;
  std::string odom_topic;   // nav_msgs/Odometry giving T_fixed_base (with base -> camera from /tf_static or
                            // T_base_camera below)
  std::string fixed_frame;  // /tf's frame the poses are given in; empty: the root of the camera's tf tree
  // Used where the recording has no pose for the camera: the optical frame on base_link (a calibration,
  // a scenario's camera mount), and base_link in the fixed frame (a static camera).
  Eigen::Isometry3d T_base_camera = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_fixed_base = Eigen::Isometry3d::Identity();
  // PNG folders without timestamps: frame k at k / rate_hz.
  double rate_hz = 30.0;
  // Range the camera's intrinsics get (recordings do not state it): depth outside it is kept as recorded.
  double min_range_m = 0.1, max_range_m = 10.0;
};

// Where a recording's poses come from.
enum class PoseSource {
  kTf,        // /tf + /tf_static: fixed_frame -> the image's frame_id
  kOdometry,  // odom_topic's T_fixed_base, then base -> camera
  kFile,      // a PNG folder's poses file (or per-frame calibration)
  kStatic,    // none in the recording: options.T_fixed_base * options.T_base_camera for every frame
};
const char* to_string(PoseSource source);

// One topic of a bag and what a replay makes of it.
struct TopicSummary {
  std::string name, type;  // type as recorded ("sensor_msgs/msg/Image", "sensor_msgs/Image" in ROS 1)
  std::uint64_t messages = 0;
  std::string message_encoding;  // rosbag2: "cdr", "json", ...; ROS 1: "ros1"
  std::string schema_encoding;   // rosbag2: "ros2msg", "ros2idl", ...; "" where none is recorded; ROS 1: "ros1msg"
  std::string use;  // "depth", "camera_info", "tf", "tf_static", "odometry", "depth_units" (librealsense); "": not read
  std::string note;  // why a topic is not read, where that is worth saying
};

struct RecordingInfo {
  std::string path;
  std::string format;                   // "ros1 bag (realsense-ros)", "ros1 bag (librealsense)", "png folder"
  std::string depth_topic, info_topic;  // bags only
  std::string encoding;                 // "16UC1", "mono16", "32FC1", "png16"
  double depth_unit_m = 0.001;  // metres per count of 16-bit depth (librealsense's Depth Units; 0.001 otherwise)
  std::string camera_frame;     // the images' frame_id (bags), "camera" otherwise
  std::string fixed_frame;      // the frame poses are in ("odom", "map", ..., or "world" for static poses)
  PoseSource pose_source = PoseSource::kStatic;
  std::size_t frame_count = 0;              // depth frames in the recording
  sensors::CameraIntrinsics intrinsics;     // of the first frame (min/max range from the options)
  double start_time_s = 0, end_time_s = 0;  // recorded stamps of the first and last depth frame
  std::vector<TopicSummary> topics;         // bags: every topic, read or not, by name
  std::vector<std::string> files;           // what was read: the bag, a rosbag2 folder's files in order, the folder
};

struct RecordedFrame {
  std::size_t index = 0;      // 0, 1, ... in recorded order
  double stamp_s = 0;         // the recording's own time (header stamp or timestamps file)
  double time_s = 0;          // stamp_s - info().start_time_s: 0 for the first frame
  sensors::DepthImage depth;  // metres along the optical axis, 0 = invalid
  sensors::CameraIntrinsics intrinsics;
  Eigen::Isometry3d T_fixed_camera = Eigen::Isometry3d::Identity();  // optical frame (z forward, x right, y down)
  Eigen::Isometry3d T_fixed_base =
      Eigen::Isometry3d::Identity();  // base_link (T_fixed_camera * inverse of base -> camera)
};

class Recording {
 public:
  virtual ~Recording() = default;
  virtual const RecordingInfo& info() const = 0;
  // The next frame into `frame` (its buffers reused); false after the last. Throws std::invalid_argument for a
  // frame that cannot be read (a truncated chunk, a bad image, no pose at its time).
  virtual bool next(RecordedFrame& frame) = 0;
};

// A bag file (by its content, not its name) or a folder; throws std::invalid_argument for anything else.
std::unique_ptr<Recording> open_recording(const std::string& path, const RecordingOptions& options = {});

// What a bag holds, without choosing a depth topic (replay --list-topics): its format, files and every topic
// (`use` left empty). Throws std::invalid_argument as open_recording; a PNG folder has no topics.
struct RecordingContents {
  std::string path, format;
  std::vector<std::string> files;
  std::vector<TopicSummary> topics;
  std::vector<std::string> warnings;
};
RecordingContents list_recording(const std::string& path);

}  // namespace stvl::recording

#pragma once
// The ROS 2 messages the bench writes and reads (not part of the interface): their .msg definitions as rosbag2
// stores them (the type, then each type it uses after a line of 80 '=' and "MSG: pkg/Type"), a check that a
// recorded definition parses and has the fields we decode, and the decoders of what a replay reads.
#include <cstdint>
#include <string>
#include <vector>

#include "common/units.hpp"

namespace stvl::recording::detail {

// "sensor_msgs/msg/Image" and "sensor_msgs/Image" -> "sensor_msgs/Image".
std::string short_type(const std::string& type);
// The full ros2msg definition of a type we write (e.g. "sensor_msgs/msg/Image"); throws std::logic_error else.
std::string ros2_definition(const std::string& type);

// Throws std::invalid_argument("<what>: ...") when `definition` is not ros2msg text (a line that is neither a
// field, a constant, a comment nor a separator) or, for a type we decode, lacks the fields we read, in order.
void check_ros2_schema(const std::string& type, const std::string& definition, const std::string& what);

struct Stamp {
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;
  double seconds() const { return sec + nanosec * kSecondsPerNanosecond; }
};

struct ImageMsg {
  Stamp stamp;
  std::string frame_id, encoding;
  std::uint32_t height = 0, width = 0, step = 0;
  bool is_bigendian = false;
  const std::uint8_t* data = nullptr;  // into the message's bytes
  std::size_t data_size = 0;
};
struct CameraInfoMsg {
  Stamp stamp;
  std::uint32_t height = 0, width = 0;
  double k[9] = {};
};
struct TransformMsg {
  Stamp stamp;
  std::string parent, child;
  double t[3] = {}, q[4] = {0, 0, 0, 1};  // x y z, x y z w
};
struct OdometryMsg {
  Stamp stamp;
  std::string frame_id, child_frame_id;
  double p[3] = {}, q[4] = {0, 0, 0, 1};
};

// Decoders of CDR messages; throw std::invalid_argument("<what>: ...") for a message shorter than its type.
// decode_image with header_only stops after the encoding (for counting frames).
ImageMsg decode_image(const std::uint8_t* data, std::size_t size, const std::string& what, bool header_only = false);
CameraInfoMsg decode_camera_info(const std::uint8_t* data, std::size_t size, const std::string& what);
std::vector<TransformMsg> decode_tf(const std::uint8_t* data, std::size_t size, const std::string& what);
OdometryMsg decode_odometry(const std::uint8_t* data, std::size_t size, const std::string& what);

}  // namespace stvl::recording::detail

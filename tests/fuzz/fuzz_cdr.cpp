// ROS 2 CDR (recording/cdr.hpp, ros2_msgs.cpp): any bytes decoded as each message type a replay reads, and any
// text checked as a ros2msg schema, either give a value or throw std::invalid_argument naming what was read;
// never read past the end (ASan), never another exception.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "recording/ros2_msgs.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace stvl::recording::detail;
  const std::string what = "fuzz";
  auto named = [&](const std::invalid_argument& e) {
    if (std::string(e.what()).rfind(what, 0) != 0) std::abort();
  };
  try {
    const ImageMsg m = decode_image(data, size, what);
    if (m.data_size && (m.data < data || m.data + m.data_size > data + size)) std::abort();
  } catch (const std::invalid_argument& e) {
    named(e);
  }
  try {
    decode_camera_info(data, size, what);
  } catch (const std::invalid_argument& e) {
    named(e);
  }
  try {
    decode_tf(data, size, what);
  } catch (const std::invalid_argument& e) {
    named(e);
  }
  try {
    decode_odometry(data, size, what);
  } catch (const std::invalid_argument& e) {
    named(e);
  }
  try {
    check_ros2_schema("sensor_msgs/msg/Image", std::string(reinterpret_cast<const char*>(data), size), what);
  } catch (const std::invalid_argument& e) {
    named(e);
  }
  return 0;
}

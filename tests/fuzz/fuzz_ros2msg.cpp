// The ros2msg parser (recording/ros2msg.hpp): any text parsed as a message, a service event and an action
// feedback type either gives types whose fields are well formed or throws MsgParseError naming a line of the
// text; the layout check of the decoded types throws std::invalid_argument naming the topic; never another
// exception, never a read out of bounds (ASan). Seeds: tests/fuzz/corpus/ros2msg, and ROS 2's own .msg files from
// ../shared/ros2_msgs where scripts/fuzz.sh finds them.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "recording/ros2_msgs.hpp"
#include "recording/ros2msg.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace stvl::recording::detail;
  const std::string text(reinterpret_cast<const char*>(data), size);
  int lines = 1;
  for (const char c : text) lines += c == '\n';
  for (const char* type : {"p/msg/T", "p/srv/T_Event", "p/action/T_FeedbackMessage"}) {
    try {
      const MsgSchema schema = parse_ros2msg(type, text);
      if (schema.types.empty()) std::abort();
      for (const auto& t : schema.types)
        for (const auto* list : {&t.fields, &t.constants})
          for (const auto& f : *list) {
            if (f.name.empty() || f.type.empty() || f.line < 1 || f.line > lines) std::abort();
            if (f.array != MsgField::Array::kNone && f.array != MsgField::Array::kUnbounded && f.array_size == 0)
              std::abort();
          }
    } catch (const MsgParseError& e) {
      if (e.line < 1 || e.line > lines) std::abort();
    }
  }
  for (const char* type :
       {"sensor_msgs/msg/Image", "sensor_msgs/msg/CameraInfo", "tf2_msgs/msg/TFMessage", "nav_msgs/msg/Odometry"}) {
    try {
      check_ros2_schema(type, text, "fuzz");
    } catch (const std::invalid_argument& e) {
      if (std::string(e.what()).rfind("fuzz", 0) != 0) std::abort();
    }
  }
  return 0;
}

#pragma once
// The ros2msg text a ROS 2 bag embeds for a topic's type, parsed as ROS 2 defines it (rosidl_adapter's
// parser.py; the MCAP registry's ros2msg; @foxglove/rosmsg agrees): the type's .msg text, then each type it uses
// after a line of '=' and "MSG: pkg/Type" (or pkg/msg/Type). Not part of the interface.
//
// A line is a field `TYPE NAME [DEFAULT]`, a constant `TYPE NAME=VALUE`, a comment or empty. A comment starts at
// a '#' outside a quoted string value. TYPE is a primitive (bool byte char float32 float64 int8..uint64 string
// wstring), `string<=N`, or a message type (`pkg/Type`, `pkg/msg/Type`, or a bare `Type` of the enclosing
// package), each optionally an array: `[N]` (fixed), `[<=N]` (bounded), `[]` (unbounded).
// A service's or action's text (a main type under pkg/srv/ or pkg/action/, e.g. the X_Event types rosbag2 records)
// has parts separated by `---`: they become the types pkg/srv/X_Request, X_Response (pkg/action/X_Goal, X_Result,
// X_Feedback) after the main type, which then has no fields of its own.
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace stvl::recording::detail {

struct MsgField {
  enum class Array { kNone, kFixed, kBounded, kUnbounded };
  std::string name;
  // A primitive's name ("uint32", "string"), or a message type as "pkg/msg/Type" (a bare name takes the
  // enclosing type's package).
  std::string type;
  bool primitive = true;
  std::uint32_t string_bound = 0;  // N of string<=N / wstring<=N; 0 unbounded
  Array array = Array::kNone;
  std::uint32_t array_size = 0;  // N of [N] and [<=N]
  std::string value;             // a constant's value or a field's default as written, quotes and all; may be empty
  int line = 0;                  // 1-based, in the whole text
};

struct MsgType {
  std::string name;  // "pkg/msg/Type" (the main type's as given to the parser, sections' from their MSG: line)
  std::vector<MsgField> fields, constants;
};

struct MsgSchema {
  std::vector<MsgType> types;  // types[0] is the main type, then the sections in order
  // The type called `name` ("pkg/Type" or "pkg/msg/Type"), or nullptr.
  const MsgType* find(const std::string& name) const;
};

// What does not parse: `line` (1-based) and `text` (the line) with what was expected there.
struct MsgParseError : std::invalid_argument {
  MsgParseError(int line, std::string text, const std::string& expected);
  int line;
  std::string text;
};

// "sensor_msgs/Image", "sensor_msgs/msg/Image" -> "sensor_msgs/msg/Image"; anything else unchanged.
std::string full_msg_type(const std::string& type);

// Parses a ros2msg text for `type` (its name for the main section, "pkg/msg/Type" or "pkg/Type"); throws
// MsgParseError for a line that is neither a field, a constant, a comment, a separator nor a section name, a
// value that does not fit its type, a name used twice in a type, or a section whose MSG: line names no pkg/Type. A
// type defined twice (older rosbag2 writes shared dependencies again) is found by its first definition.
MsgSchema parse_ros2msg(const std::string& type, const std::string& text);

}  // namespace stvl::recording::detail

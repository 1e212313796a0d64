// The ros2msg parser (recording/ros2msg.hpp): ROS 2's own .msg texts as rosbag2 embeds them (../shared/ros2_msgs,
// comments and all), texts written here with every awkward case of the grammar, and what must not parse.
#include "recording/ros2msg.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "recording/ros2_msgs.hpp"

namespace stvl::recording::detail {
namespace {

namespace fs = std::filesystem;
const fs::path kRos2Msgs = fs::path(STVL_REALDATA_DIR).parent_path() / "ros2_msgs";

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// "pkg/msg/Type" -> its .msg file under ../shared/ros2_msgs.
fs::path msg_file(const std::string& full_type) {
  const auto slash = full_type.find('/');
  return kRos2Msgs / full_type.substr(0, slash) / "msg" / (full_type.substr(full_type.rfind('/') + 1) + ".msg");
}

// A type's text as `ros2 bag record` embeds it: its .msg file, then each type it uses (depth first, once) after a
// line of 80 '=' and "MSG: pkg/Type"; false when a dependency's file is missing.
bool concatenate_as_rosbag2(const std::string& type, std::string& text) {
  std::vector<std::string> order{full_msg_type(type)};
  std::set<std::string> seen{order.front()};
  for (std::size_t i = 0; i < order.size(); ++i) {
    if (!fs::exists(msg_file(order[i]))) return false;
    const MsgSchema schema = parse_ros2msg(order[i], read_text(msg_file(order[i])));
    for (const auto& f : schema.types.front().fields)
      if (!f.primitive && seen.insert(f.type).second) order.push_back(f.type);
  }
  text = read_text(msg_file(order.front()));
  for (std::size_t i = 1; i < order.size(); ++i)
    text += "\n" + std::string(80, '=') + "\nMSG: " + short_type(order[i]) + "\n" + read_text(msg_file(order[i]));
  return true;
}

TEST(Ros2Msg, ParsesEveryMsgFileOfRos2AsRosbag2EmbedsIt) {
  if (!fs::exists(kRos2Msgs)) GTEST_SKIP() << kRos2Msgs << " is absent (it lies beside the checkout in CI)";
  int files = 0;
  for (const auto& pkg : fs::directory_iterator(kRos2Msgs)) {
    if (!fs::is_directory(pkg.path() / "msg")) continue;
    for (const auto& file : fs::directory_iterator(pkg.path() / "msg")) {
      const std::string type = pkg.path().filename().string() + "/msg/" + file.path().stem().string();
      SCOPED_TRACE(type);
      std::string text;
      ASSERT_TRUE(concatenate_as_rosbag2(type, text)) << "a dependency's .msg is missing";
      const MsgSchema schema = parse_ros2msg(type, text);
      EXPECT_EQ(schema.types.front().name, type);
      EXPECT_FALSE(schema.types.front().fields.empty());
      for (const auto& t : schema.types)
        for (const auto& f : t.fields)
          if (!f.primitive) {
            EXPECT_NE(schema.find(f.type), nullptr) << t.name << "." << f.name << ": " << f.type;
          }
      // The types the replay decodes have the fields the decoders read, in order.
      EXPECT_NO_THROW(check_ros2_schema(type, text, "test"));
      ++files;
    }
  }
  EXPECT_GE(files, 15);
}

TEST(Ros2Msg, Ros2OwnTextsOfTheDecodedTypesPassTheLayoutCheckAndTheirCommentsAreGone) {
  if (!fs::exists(kRos2Msgs)) GTEST_SKIP() << kRos2Msgs << " is absent (it lies beside the checkout in CI)";
  std::string text;
  ASSERT_TRUE(concatenate_as_rosbag2("tf2_msgs/msg/TFMessage", text));
  ASSERT_NE(text.find("<a href="), std::string::npos);  // the comment that stopped the old reader
  const MsgSchema tf = parse_ros2msg("tf2_msgs/msg/TFMessage", text);
  ASSERT_EQ(tf.types.front().fields.size(), 1u);
  EXPECT_EQ(tf.types.front().fields[0].type, "geometry_msgs/msg/TransformStamped");
  EXPECT_EQ(tf.types.front().fields[0].array, MsgField::Array::kUnbounded);
  ASSERT_TRUE(concatenate_as_rosbag2("sensor_msgs/msg/CameraInfo", text));
  const MsgSchema info = parse_ros2msg("sensor_msgs/CameraInfo", text);
  const auto& k = info.types.front().fields.at(5);
  EXPECT_EQ(k.name, "k");
  EXPECT_EQ(k.array, MsgField::Array::kFixed);
  EXPECT_EQ(k.array_size, 9u);
  // PointField's constants are constants, not fields.
  ASSERT_TRUE(concatenate_as_rosbag2("sensor_msgs/msg/PointField", text));
  const MsgSchema field = parse_ros2msg("sensor_msgs/msg/PointField", text);
  EXPECT_EQ(field.types.front().fields.size(), 4u);
  EXPECT_EQ(field.types.front().constants.size(), 8u);
}

TEST(Ros2Msg, CommentsStartAtAHashOutsideQuotedValues) {
  const MsgSchema s = parse_ros2msg("p/msg/T",
                                    "# file comment with = and 'quotes\n"
                                    "string FOO=\"a#b\"  # the constant holds a#b\n"
                                    "string BAR='c # d'\n"
                                    "int8 X=-1 # minus one\n"
                                    "string s \"hi # there\" # default with a hash\n"
                                    "  # an indented comment = 3\n"
                                    "int32 y # y = 2 'quote\n"
                                    "\tfloat64\tz\t\n");
  const MsgType& t = s.types.front();
  ASSERT_EQ(t.constants.size(), 3u);
  EXPECT_EQ(t.constants[0].name, "FOO");
  EXPECT_EQ(t.constants[0].value, "\"a#b\"");
  EXPECT_EQ(t.constants[1].value, "'c # d'");
  EXPECT_EQ(t.constants[2].value, "-1");
  ASSERT_EQ(t.fields.size(), 3u);
  EXPECT_EQ(t.fields[0].value, "\"hi # there\"");
  EXPECT_EQ(t.fields[1].name, "y");
  EXPECT_TRUE(t.fields[1].value.empty());
  EXPECT_EQ(t.fields[2].type, "float64");
  EXPECT_EQ(t.fields[2].line, 8);
}

TEST(Ros2Msg, DefaultsBoundsArraysAndSectionNames) {
  const MsgSchema s = parse_ros2msg("p/T",
                                    "int32 x 5\n"
                                    "float64[] v [1.0, 2.0]\n"
                                    "string<=5 name \"abc\"\n"
                                    "string[3] words [\"a,b\", 'c', \"\"]\n"
                                    "int16[<=4] few [1, -2]\n"
                                    "bool[2] flags [true, 0]\n"
                                    "uint8 HEX=0x1f\n"
                                    "Inner bare\n"
                                    "q/Other[<=3] bounded\n"
                                    "q/msg/Third[2] fixed\n"
                                    "================================================================================\n"
                                    "MSG: p/Inner\n"
                                    "float32 a\n"
                                    "===\n"
                                    "MSG: q/msg/Other\n"
                                    "===\n"
                                    "MSG: q/Third\n"
                                    "wstring<=3 w\n");
  ASSERT_EQ(s.types.size(), 4u);
  EXPECT_EQ(s.types[0].name, "p/msg/T");
  const auto& f = s.types[0].fields;
  ASSERT_EQ(f.size(), 9u);
  EXPECT_EQ(f[0].value, "5");
  EXPECT_EQ(f[1].array, MsgField::Array::kUnbounded);
  EXPECT_EQ(f[2].string_bound, 5u);
  EXPECT_EQ(f[3].array, MsgField::Array::kFixed);
  EXPECT_EQ(f[3].array_size, 3u);
  EXPECT_EQ(f[4].array, MsgField::Array::kBounded);
  EXPECT_EQ(f[4].array_size, 4u);
  EXPECT_EQ(f[6].type, "p/msg/Inner");  // a bare name is the enclosing package's
  EXPECT_FALSE(f[6].primitive);
  EXPECT_EQ(f[7].type, "q/msg/Other");
  EXPECT_EQ(f[8].type, "q/msg/Third");
  EXPECT_EQ(s.types[0].constants.at(0).value, "0x1f");
  ASSERT_NE(s.find("q/Other"), nullptr);
  EXPECT_TRUE(s.find("q/Other")->fields.empty());  // an empty message
  ASSERT_NE(s.find("q/msg/Third"), nullptr);
  EXPECT_EQ(s.find("q/msg/Third")->fields.at(0).string_bound, 3u);
  EXPECT_EQ(s.find("p/msg/Missing"), nullptr);
}

TEST(Ros2Msg, ServiceTextsBecomeRequestAndResponse) {
  const MsgSchema s = parse_ros2msg("example_interfaces/srv/AddTwoInts_Event", "int64 a\nint64 b\n---\nint64 sum\n");
  ASSERT_EQ(s.types.size(), 3u);
  EXPECT_TRUE(s.types[0].fields.empty());
  EXPECT_EQ(s.types[1].name, "example_interfaces/srv/AddTwoInts_Request");
  EXPECT_EQ(s.types[1].fields.size(), 2u);
  EXPECT_EQ(s.types[2].name, "example_interfaces/srv/AddTwoInts_Response");
  EXPECT_EQ(s.types[2].fields.at(0).name, "sum");
  const MsgSchema a =
      parse_ros2msg("p/action/Fib_FeedbackMessage", "int32 order\n---\nint32[] seq\n---\nint32[] part\n");
  ASSERT_EQ(a.types.size(), 4u);
  EXPECT_EQ(a.types[3].name, "p/action/Fib_Feedback");
  // In a message, '---' is no separator.
  EXPECT_THROW(parse_ros2msg("p/msg/T", "int32 a\n---\nint32 b\n"), MsgParseError);
}

TEST(Ros2Msg, WhatDoesNotParseSaysTheLineAndWhatWasExpected) {
  const std::map<std::string, std::string> bad = {
      {"int32\n", "TYPE NAME"},
      {"int32 x\nfloat64 x\n", "not used before"},
      {"int32 x y z\n", "an integer"},
      {"int8 X=200\n", "from -128 to 127"},
      {"uint8 X=-1\n", "from 0 to 255"},
      {"bool B=maybe\n", "true, false"},
      {"float64 f abc\n", "floating point"},
      {"string<=2 s \"abc\"\n", "at most 2 characters"},
      {"int32[2] v [1, 2, 3]\n", "exactly 2 elements"},
      {"int32[<=1] v [1, 2]\n", "at most 1 elements"},
      {"int32[] v 1, 2\n", "[a, b, ...]"},
      {"int32[0] v\n", "integer > 0"},
      {"int32[x] v\n", "integer > 0"},
      {"string<=0 s\n", "integer > 0"},
      {"int32<=3 s\n", "string or wstring only"},
      {"int32[3] X=1\n", "primitive, non-array"},
      {"p/Inner X=1\n", "primitive, non-array"},
      {"p/Inner i 3\n", "a message type takes none"},
      {"Bad/Type!x y\n", "message type"},
      {"int32 9lives\n", "a name"},
      {"string s \"a\"b\"\n", "escaped"},
      {"int32 x\n====\nint32 y\n", "MSG: pkg/Type"},
      {"int32 x\n====\nMSG: notatype\n", "MSG: pkg/Type"},
      {"int32 x\n====\nIDL: p/msg/Y\n", "IDL: section"},
      {"int32 x\n====\n", "after the last line"},
  };
  for (const auto& [text, expected] : bad) {
    SCOPED_TRACE(text);
    try {
      parse_ros2msg("p/msg/T", text);
      ADD_FAILURE() << "parsed";
    } catch (const MsgParseError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
      EXPECT_GE(e.line, 1);
    }
  }
  try {
    parse_ros2msg("p/msg/T", "# ok\nint32 a\n\nfloat64 b 1.5\nint8 c 300\n");
    ADD_FAILURE() << "parsed";
  } catch (const MsgParseError& e) {
    EXPECT_EQ(e.line, 5);
    EXPECT_EQ(e.text, "int8 c 300");
    EXPECT_NE(std::string(e.what()).find("line 5: 'int8 c 300'"), std::string::npos) << e.what();
  }
}

TEST(Ros2Msg, TheLayoutCheckNamesTheFieldThatDiffers) {
  const auto check = [](const std::string& type, const std::string& text) {
    try {
      check_ros2_schema(type, text, "bag.mcap: topic /x");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  // Our own definitions pass.
  for (const char* type :
       {"sensor_msgs/msg/Image", "sensor_msgs/msg/CameraInfo", "tf2_msgs/msg/TFMessage", "nav_msgs/msg/Odometry"})
    EXPECT_EQ(check(type, ros2_definition(type)), "") << type;
  // A field of another type, a field missing, a nested type that differs, a nested type not defined.
  std::string image = ros2_definition("sensor_msgs/msg/Image");
  std::string wrong = image;
  wrong.replace(wrong.find("uint32 step"), 11, "uint16 step");
  EXPECT_NE(check("sensor_msgs/msg/Image", wrong).find("field 6 is 'uint16 step', expected 'uint32 step'"),
            std::string::npos);
  EXPECT_NE(check("sensor_msgs/msg/Image", "std_msgs/Header header\nuint32 height\n").find("expected at least 7"),
            std::string::npos);
  wrong = image;
  wrong.replace(wrong.find("uint32 nanosec"), 14, "uint64 nanosec");
  EXPECT_NE(check("sensor_msgs/msg/Image", wrong).find("builtin_interfaces/msg/Time field 2"), std::string::npos);
  // A schema without its dependencies' sections: their names stand for them.
  EXPECT_EQ(check("sensor_msgs/msg/Image", image.substr(0, image.find("===="))), "");
  EXPECT_NE(check("sensor_msgs/msg/Image", "int32 x\nint32 x\n").find("does not parse (line 2"), std::string::npos);
  // Types no decoder reads only have to parse.
  EXPECT_EQ(check("std_msgs/msg/String", "string data # hi\n"), "");
}

}  // namespace
}  // namespace stvl::recording::detail

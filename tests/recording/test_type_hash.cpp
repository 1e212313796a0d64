// ROS 2's type description hashes (RIHS01): proven against a bag rosbag2 recorded itself, against ROS 2's own .msg
// texts and the hashes its code generators publish, on a hand-made type, and in the metadata.yaml we write.
#include "recording/type_hash.hpp"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "recording/bag_writer.hpp"
#include "recording/mcap.hpp"
#include "recording/ros2_msgs.hpp"
#include "tests/support/command.hpp"

namespace stvl::recording::detail {
namespace {

namespace fs = std::filesystem;

const std::regex kRihs01("RIHS01_[0-9a-f]{64}");

MsgField field(const std::string& name, const std::string& type, MsgField::Array array = MsgField::Array::kNone,
               std::uint32_t array_size = 0, std::uint32_t string_bound = 0) {
  MsgField f;
  f.name = name, f.type = type, f.array = array, f.array_size = array_size, f.string_bound = string_bound;
  f.primitive = type.find('/') == std::string::npos;
  return f;
}

MsgType msg_type(const std::string& name, std::vector<MsgField> fields) {
  MsgType t;
  t.name = name, t.fields = std::move(fields);
  return t;
}

std::uint64_t le(const std::string& bytes, std::size_t at, int size) {
  std::uint64_t v = 0;
  for (int i = size - 1; i >= 0; --i) v = v << 8 | static_cast<unsigned char>(bytes.at(at + i));
  return v;
}

// The schemas an MCAP file carries: name -> {encoding, data}. Those of the data section come from McapReader; a
// schema no message uses (a topic without messages) is only in the summary, whose records are read here (the
// file's top-level records: opcode, u64 length, body; a Schema is u16 id, then three u32-prefixed strings).
std::map<std::string, std::pair<std::string, std::string>> mcap_schemas(const std::string& path) {
  std::map<std::string, std::pair<std::string, std::string>> schemas;
  McapReader reader(path);
  McapRecord record;
  while (reader.next(record)) {
    if (record.kind == McapRecord::kSchema) schemas[record.schema.name] = {record.schema.encoding, record.schema.data};
  }
  std::ifstream in(path, std::ios::binary);
  const std::string file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  constexpr std::size_t kMagicBytes = 8, kRecordHeaderBytes = 9;
  constexpr int kOpSchema = 0x03, kOpFooter = 0x02;
  for (std::size_t at = kMagicBytes; at + kRecordHeaderBytes <= file.size();) {
    const int op = static_cast<unsigned char>(file[at]);
    const std::uint64_t length = le(file, at + 1, 8);
    if (op == kOpFooter) break;
    if (op == kOpSchema) {
      std::size_t p = at + kRecordHeaderBytes + 2;
      std::string fields[3];
      for (auto& f : fields) {
        const std::uint64_t n = le(file, p, 4);
        f = file.substr(p + 4, n), p += 4 + n;
      }
      schemas.emplace(fields[0], std::make_pair(fields[1], fields[2]));
    }
    at += kRecordHeaderBytes + length;
  }
  return schemas;
}

// metadata.yaml's topics: type -> type_description_hash (every topic of a type must carry the same).
std::map<std::string, std::string> metadata_hashes(const fs::path& metadata) {
  std::map<std::string, std::string> hashes;
  const YAML::Node topics =
      YAML::LoadFile(metadata.string())["rosbag2_bagfile_information"]["topics_with_message_count"];
  for (const auto& t : topics) {
    const YAML::Node m = t["topic_metadata"];
    const std::string type = m["type"].as<std::string>();
    const std::string hash = m["type_description_hash"] ? m["type_description_hash"].as<std::string>() : "<none>";
    const auto [it, inserted] = hashes.emplace(type, hash);
    EXPECT_EQ(it->second, hash) << "two hashes for " << type;
  }
  return hashes;
}

TEST(TypeHashTest, Sha256OfKnownVectors) {
  // FIPS 180-2, appendix B.1, and the empty message.
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
}

// Every kind of field: a bounded string, a fixed array, a bounded sequence (its bound is the capacity), a nested
// type, a sequence of an empty message (which gets rosidl's one uint8 member), bounded strings in a sequence, char
// (uint8) and byte (octet). The JSON and its hash were written out by Python's json.dumps and hashlib.
TEST(TypeHashTest, HandMadeTypeGivesRosidlsJsonAndHash) {
  MsgSchema schema;
  schema.types = {
      msg_type(
          "hand_msgs/msg/Mixed",
          {field("name", "string", MsgField::Array::kNone, 0, 8), field("xyz", "float32", MsgField::Array::kFixed, 3),
           field("samples", "int16", MsgField::Array::kBounded, 5), field("inner", "hand_msgs/msg/Inner"),
           field("empties", "hand_msgs/msg/Empty", MsgField::Array::kUnbounded),
           field("labels", "string", MsgField::Array::kUnbounded, 0, 4), field("c", "char"), field("b", "byte")}),
      msg_type("hand_msgs/msg/Inner", {field("flag", "bool"), field("x", "float64")}), msg_type("hand_msgs/Empty", {})};
  MsgField constant = field("ANSWER", "int32");
  constant.value = "42";
  schema.types[0].constants.push_back(constant);  // constants are not hashed
  schema.types[0].fields[1].value = "[1, 2, 3]";  // nor default values
  const std::string expected_json =
      R"({"type_description": {"type_name": "hand_msgs/msg/Mixed", "fields": [)"
      R"({"name": "name", "type": {"type_id": 21, "capacity": 0, "string_capacity": 8, "nested_type_name": ""}}, )"
      R"({"name": "xyz", "type": {"type_id": 58, "capacity": 3, "string_capacity": 0, "nested_type_name": ""}}, )"
      R"({"name": "samples", "type": {"type_id": 100, "capacity": 5, "string_capacity": 0, "nested_type_name": ""}}, )"
      R"({"name": "inner", "type": {"type_id": 1, "capacity": 0, "string_capacity": 0, )"
      R"("nested_type_name": "hand_msgs/msg/Inner"}}, )"
      R"({"name": "empties", "type": {"type_id": 145, "capacity": 0, "string_capacity": 0, )"
      R"("nested_type_name": "hand_msgs/msg/Empty"}}, )"
      R"({"name": "labels", "type": {"type_id": 165, "capacity": 0, "string_capacity": 4, "nested_type_name": ""}}, )"
      R"({"name": "c", "type": {"type_id": 3, "capacity": 0, "string_capacity": 0, "nested_type_name": ""}}, )"
      R"({"name": "b", "type": {"type_id": 16, "capacity": 0, "string_capacity": 0, "nested_type_name": ""}}]}, )"
      R"("referenced_type_descriptions": [{"type_name": "hand_msgs/msg/Empty", "fields": [)"
      R"({"name": "structure_needs_at_least_one_member", "type": {"type_id": 3, "capacity": 0, )"
      R"("string_capacity": 0, "nested_type_name": ""}}]}, {"type_name": "hand_msgs/msg/Inner", "fields": [)"
      R"({"name": "flag", "type": {"type_id": 15, "capacity": 0, "string_capacity": 0, "nested_type_name": ""}}, )"
      R"({"name": "x", "type": {"type_id": 11, "capacity": 0, "string_capacity": 0, "nested_type_name": ""}}]}]})";
  EXPECT_EQ(ros2_type_description_json("hand_msgs/Mixed", schema), expected_json);
  const TypeHash hash = ros2_type_hash("hand_msgs/msg/Mixed", schema);
  EXPECT_EQ(hash.rihs01, "RIHS01_9966d375a306f39af697a87b65b1e81e4e903b6846c564a7342e63211b3e7cbb") << hash.reason;
  EXPECT_TRUE(hash.reason.empty());

  MsgSchema empty;
  empty.types = {msg_type("hand_msgs/msg/Empty", {})};
  EXPECT_EQ(ros2_type_hash("hand_msgs/msg/Empty", empty).rihs01,
            "RIHS01_e7d6f6ed7477e0e0923197f6be2fc6167b229113723068692a18b137534367e2");
}

TEST(TypeHashTest, WhatCannotBeHashedIsEmptyWithAReason) {
  MsgSchema schema;
  schema.types = {msg_type("a_msgs/msg/Outer", {field("inner", "b_msgs/msg/Missing")})};
  TypeHash hash = ros2_type_hash("a_msgs/msg/Outer", schema);
  EXPECT_EQ(hash.rihs01, "");
  EXPECT_NE(hash.reason.find("no definition of b_msgs/msg/Missing"), std::string::npos) << hash.reason;
  EXPECT_THROW(ros2_type_description_json("a_msgs/msg/Outer", schema), std::invalid_argument);

  hash = ros2_type_hash_of_schema("a_msgs/msg/T", "ros2idl", "module a_msgs { module msg { struct T {}; }; };");
  EXPECT_EQ(hash.rihs01, "");
  EXPECT_NE(hash.reason.find("ros2idl"), std::string::npos) << hash.reason;
  hash = ros2_type_hash_of_schema("a_msgs/msg/T", "ros2msg", "IDL: a_msgs/msg/T\nmodule a_msgs {};\n");
  EXPECT_EQ(hash.rihs01, "");
  EXPECT_NE(hash.reason.find("IDL"), std::string::npos) << hash.reason;
  hash = ros2_type_hash_of_schema("a_msgs/action/Fibonacci_FeedbackMessage", "ros2msg", "int32 order\n");
  EXPECT_EQ(hash.rihs01, "");
  EXPECT_NE(hash.reason.find("action"), std::string::npos) << hash.reason;
  hash = ros2_type_hash_of_schema("a_msgs/srv/AddTwoInts_Event", "ros2msg", "int64 a\nint64 b\n");
  EXPECT_EQ(hash.rihs01, "");
  EXPECT_NE(hash.reason.find("---"), std::string::npos) << hash.reason;
  hash = ros2_type_hash_of_schema("a_msgs/msg/T", "ros2msg", "not a field line at all\n");
  EXPECT_EQ(hash.rihs01, "");
  EXPECT_FALSE(hash.reason.empty());
}

// The proof: rosbag2 recorded this bag itself (ros2/rosbag2's rosbag2_py test resources; see realdata/README.md)
// and wrote each topic's type_description_hash from the type support of the running nodes. Each schema the MCAP
// file carries hashes to the same value: a message with bounded strings, defaults and a constant
// (test_msgs/msg/Strings), a message whose schema has comments (rosbag2_interfaces/msg/WriteSplitEvent), and a
// service event whose schema is the .srv text (test_msgs/srv/BasicTypes_Event: char, byte, every primitive, and
// request/response as bounded sequences [<=1], which only match with their bound 1 as the capacity).
TEST(TypeHashTest, MatchesTheHashesRosbag2RecordedItself) {
  const fs::path folder = fs::path(STVL_REALDATA_DIR) / "rosbag2" / "service_events_mcap";
  if (!fs::exists(folder / "metadata.yaml")) GTEST_SKIP() << folder << " is absent (../shared/realdata)";
  const auto expected = metadata_hashes(folder / "metadata.yaml");
  const auto schemas = mcap_schemas((folder / "bag_with_topics_and_service_events.mcap").string());
  const std::vector<std::string> types = {"rosbag2_interfaces/msg/WriteSplitEvent", "test_msgs/srv/BasicTypes_Event",
                                          "test_msgs/msg/Strings"};
  for (const auto& type : types) {
    ASSERT_TRUE(expected.count(type)) << type << " not in metadata.yaml";
    ASSERT_TRUE(schemas.count(type)) << type << " has no schema in the MCAP file";
    EXPECT_TRUE(std::regex_match(expected.at(type), kRihs01)) << expected.at(type);
    const TypeHash hash = ros2_type_hash_of_schema(type, schemas.at(type).first, schemas.at(type).second);
    EXPECT_EQ(hash.rihs01, expected.at(type)) << type << ": " << hash.reason;
  }
}

// The types our rosbag2 export writes.
const std::vector<std::string> kWrittenTypes = {"rosgraph_msgs/msg/Clock",     "tf2_msgs/msg/TFMessage",
                                                "nav_msgs/msg/Odometry",       "geometry_msgs/msg/PoseStamped",
                                                "sensor_msgs/msg/Image",       "sensor_msgs/msg/CameraInfo",
                                                "sensor_msgs/msg/PointCloud2", "nav_msgs/msg/OccupancyGrid",
                                                "nav_msgs/msg/Path",           "geometry_msgs/msg/Twist"};

TypeHash hash_of_our_definition(const std::string& type) {
  return ros2_type_hash_of_schema(type, "ros2msg", ros2_definition(type));
}

// ROS 2's published hashes: the 32 bytes rosidl_generator_c writes into generated code.
// Zuhaib-Saadat/fyp-ros2, build/rtabmap_msgs/rosidl_generator_c/rtabmap_msgs/msg/detail/node__description.c
// (the *__EXPECTED_HASH of the types rtabmap_msgs/msg/Node uses): Time, Point, Pose, PoseWithCovariance,
// Quaternion, Transform, Vector3, CameraInfo, Image, PointCloud2, PointField, RegionOfInterest, Header.
// micro-ROS/micro_ros_arduino, src/<pkg>/msg/detail/<type>__struct.h (*__TYPE_HASH): Odometry, Clock, PoseStamped.
// hpmicro/hpm_sdk, middleware/microros/kilted/include/nav_msgs/nav_msgs/msg/detail/occupancy_grid__description.c:
// OccupancyGrid and MapMetaData. TFMessage: tf2_msgs__msg__TFMessage__EXPECTED_HASH in the generated
// *__description.c of two packages that use it (a my_mesh_interfaces/msg/MeshTf and an object_search_msgs build).
// Path: nav_msgs__msg__Path__EXPECTED_HASH in nav2's generated dwb_msgs/srv/detail/debug_local_plan__description.c
// (beside the PoseStamped, Header and Point hashes above) and two other builds. Twist:
// geometry_msgs__msg__Twist__EXPECTED_HASH in ten generated *__description.c files of packages that use it.
// (Two stray struct.h files give other values for Path and Twist; those are not what the *__description.c files
// that agree with every hash above assert, and ours matches the ones that do.)
const std::map<std::string, std::string> kPublishedHashes = {
    {"builtin_interfaces/msg/Time", "b106235e25a4c5ed35098aa0a61a3ee9c9b18d197f398b0e4206cea9acf9c197"},
    {"geometry_msgs/msg/Point", "6963084842a9b04494d6b2941d11444708d892da2f4b09843b9c43f42a7f6881"},
    {"geometry_msgs/msg/Pose", "d501954e9476cea2996984e812054b68026ae0bfae789d9a10b23daf35cc90fa"},
    {"geometry_msgs/msg/PoseWithCovariance", "9a7c0fd234b7f45c6098745ecccd773ca1085670e64107135397aee31c02e1bb"},
    {"geometry_msgs/msg/Quaternion", "8a765f66778c8ff7c8ab94afcc590a2ed5325a1d9a076ffff38fbce36f458684"},
    {"geometry_msgs/msg/Transform", "beb83fbe698636351461f6f35d1abb20010c43d55374d81bd041f1ba2581fddc"},
    {"geometry_msgs/msg/Vector3", "cc12fe83e4c02719f1ce8070bfd14aecd40f75a96696a67a2a1f37f7dbb0765d"},
    {"sensor_msgs/msg/CameraInfo", "b3dfd68ff46c9d56c80fd3bd4ed22c7a4ddce8c8348f2f59c299e73118e7e275"},
    {"sensor_msgs/msg/Image", "d31d41a9a4c4bc8eae9be757b0beed306564f7526c88ea6a4588fb9582527d47"},
    {"sensor_msgs/msg/PointCloud2", "9198cabf7da3796ae6fe19c4cb3bdd3525492988c70522628af5daa124bae2b5"},
    {"sensor_msgs/msg/PointField", "5c6a4750728c2bcfbbf7037225b20b02d4429634732146b742dee1726637ef01"},
    {"sensor_msgs/msg/RegionOfInterest", "ad16bcba5f9131dcdba6fbded19f726f5440e3c513b4fb586dd3027eeed8abb1"},
    {"std_msgs/msg/Header", "f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01"},
    {"nav_msgs/msg/Odometry", "3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0"},
    {"rosgraph_msgs/msg/Clock", "692f7a66e93a3c83e71765d033b60349ba68023a8c689a79e48078bcb5c58564"},
    {"geometry_msgs/msg/PoseStamped", "10f3786d7d40fd2b54367835614bff85d4ad3b5dab62bf8bca0cc232d73b4cd8"},
    {"tf2_msgs/msg/TFMessage", "e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087"},
    {"nav_msgs/msg/OccupancyGrid", "8d348150c12913a31ee0ec170fbf25089e4745d17035792a1ba94d6f0bc0cfc7"},
    {"nav_msgs/msg/MapMetaData", "2772d4b2000ef2b35dbaeb80fd3946c1369f817fb4f75677d916d27c17d763c8"},
    {"nav_msgs/msg/Path", "1957a5bb3cee5da65c4e52e52b65a93df227efce4c20f8458b36e73066ca334b"},
    {"geometry_msgs/msg/Twist", "9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a"},
};

TEST(TypeHashTest, OurDefinitionsHashAsRos2PublishesThem) {
  for (const auto& [type, hex] : kPublishedHashes) {
    const TypeHash hash = hash_of_our_definition(type);
    EXPECT_EQ(hash.rihs01, "RIHS01_" + hex) << type << ": " << hash.reason;
  }
  for (const auto& type : kWrittenTypes) EXPECT_TRUE(kPublishedHashes.count(type)) << type << " has no reference";
}

// ROS 2's own .msg files (../shared/ros2_msgs, comments and all) concatenated as rosbag2's
// LocalMessageDefinitionSource does: the type's text, then for each type it uses, once, depth first in name order,
// "\n", 80 '=', "\nMSG: pkg/Type\n" and that type's text.
std::string rosbag2_full_text(const fs::path& root, const std::string& type, std::set<std::string>& missing) {
  std::set<std::string> seen;
  std::function<std::string(const std::string&)> append = [&](const std::string& t) -> std::string {
    const auto slash = t.find('/');
    const std::string pkg = t.substr(0, slash), name = t.substr(t.rfind('/') + 1);
    std::ifstream in(root / pkg / "msg" / (name + ".msg"));
    if (!in) {
      missing.insert(pkg + "/msg/" + name);
      return "";
    }
    std::stringstream text;
    text << in.rdbuf();
    std::set<std::string> deps;  // as the fields name them: pkg/Type
    const MsgSchema schema = parse_ros2msg(pkg + "/msg/" + name, text.str());
    for (const auto& f : schema.types[0].fields) {
      if (f.primitive) continue;
      deps.insert(f.type.substr(0, f.type.find('/')) + "/" + f.type.substr(f.type.rfind('/') + 1));
    }
    std::string result = text.str();
    for (const auto& dep : deps) {
      if (seen.insert(dep).second) result += "\n" + std::string(80, '=') + "\nMSG: " + dep + "\n" + append(dep);
    }
    return result;
  };
  return append(type);
}

TEST(TypeHashTest, OurDefinitionsHashAsRos2sOwnMsgFiles) {
  const fs::path root = fs::path(STVL_SOURCE_DIR) / ".." / "shared" / "ros2_msgs";
  if (!fs::is_directory(root)) GTEST_SKIP() << root << " is absent (../shared/ros2_msgs)";
  int compared = 0;
  std::set<std::string> all_missing;
  for (const auto& type : kWrittenTypes) {
    std::set<std::string> missing;
    const std::string text = rosbag2_full_text(root, type, missing);
    if (!missing.empty()) {  // not every package is in ../shared/ros2_msgs
      all_missing.insert(missing.begin(), missing.end());
      continue;
    }
    const TypeHash theirs = ros2_type_hash_of_schema(type, "ros2msg", text);
    const TypeHash ours = hash_of_our_definition(type);
    EXPECT_TRUE(std::regex_match(theirs.rihs01, kRihs01)) << type << ": " << theirs.reason;
    EXPECT_EQ(ours.rihs01, theirs.rihs01) << type << ": " << ours.reason;
    ++compared;
  }
  std::string skipped;
  for (const auto& m : all_missing) skipped += " " + m;
  // Image, CameraInfo, PointCloud2, TFMessage and OccupancyGrid are complete there.
  EXPECT_GE(compared, 5) << "missing .msg files:" << skipped;
  if (!skipped.empty()) std::cout << "[ INFO     ] not compared (no .msg file in " << root << "):" << skipped << "\n";
}

// metadata.yaml of a bag we write: every topic has its type's hash, as rosbag2 writes it.
TEST(TypeHashTest, WriterPutsEachTopicsHashInMetadataYaml) {
  const test::TempDir dir("type_hash_writer");
  auto sink = make_bag_writer((dir.path() / "run").string(), BagFormat::kRos2, BagCompression::kZstd);
  sensors::CameraIntrinsics k;
  k.width = 4, k.height = 2, k.fx = k.fy = 3.0, k.cx = 1.5, k.cy = 0.5;
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  sink->write_clock(0.0);
  sink->write_tf(0.0, I, I);
  sink->write_tf_static({BagSink::CameraFrames{}});
  sink->write_odometry(0.0, I, 0.5, 0.1);
  sink->write_ground_truth_pose(0.0, I);
  sink->write_depth_image(0.0, k, std::vector<std::uint16_t>(8, 1000));
  sink->write_camera_info(0.0, k);
  sink->write_points("/stvl/points", 0.0, kCameraOpticalFrame, Eigen::Matrix3Xf::Zero(3, 2));
  mapping::Costmap2D costmap;
  costmap.width = 2, costmap.height = 1, costmap.cells = {0, 254};
  sink->write_costmap(0.0, costmap);
  sink->write_path(kPlanTopic, 0.0, {{1.0, 2.0, 0.5}});
  sink->write_twist(kCmdVelTopic, 0.0, 0.5, 0.1);
  sink->close();

  const fs::path folder = dir.path() / "run";
  const auto hashes = metadata_hashes(folder / "metadata.yaml");
  const auto schemas = mcap_schemas((folder / "run_0.mcap").string());
  std::set<std::string> written;
  for (const auto& [type, hash] : hashes) {
    written.insert(type);
    EXPECT_TRUE(std::regex_match(hash, kRihs01)) << type << ": '" << hash << "'";
    EXPECT_EQ(hash, hash_of_our_definition(type).rihs01) << type;
    ASSERT_TRUE(schemas.count(type)) << type;
    EXPECT_EQ(hash, ros2_type_hash_of_schema(type, schemas.at(type).first, schemas.at(type).second).rihs01) << type;
    EXPECT_EQ(hash, "RIHS01_" + kPublishedHashes.at(type)) << type;
  }
  EXPECT_EQ(written, std::set<std::string>(kWrittenTypes.begin(), kWrittenTypes.end()));
  // Each channel's metadata carries the hash too, as rosbag2's MCAP storage writes it.
  McapReader reader((folder / "run_0.mcap").string());
  McapRecord r;
  std::map<std::uint16_t, std::string> schema_types;
  int channels = 0;
  while (reader.next(r)) {
    if (r.kind == McapRecord::kSchema) schema_types[r.schema.id] = r.schema.name;
    if (r.kind != McapRecord::kChannel) continue;
    ++channels;
    ASSERT_TRUE(r.channel.metadata.count("topic_type_hash")) << r.channel.topic;
    EXPECT_EQ(r.channel.metadata.at("topic_type_hash"), hashes.at(schema_types.at(r.channel.schema_id)))
        << r.channel.topic;
  }
  EXPECT_GE(channels, 10);
}

}  // namespace
}  // namespace stvl::recording::detail

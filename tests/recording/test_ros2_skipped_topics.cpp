// A rosbag2 recording with, beside its camera topics, a topic a replay does not use must replay exactly as the
// recording without it: every other topic (service events, actions, JSON, ros2idl, protobuf, no schema, a schema
// that does not parse, a `pkg/idl/Type`) is skipped, never fatal. A small depth recording (our rosbag2 export:
// 16UC1 frames, camera_info, /tf, /tf_static) is copied record by record into MCAP files (detail::McapWriter, any
// schema and message encoding) and rosbag2 sqlite3 files (the sqlite3 C API: Humble's tables, or Jazzy's with
// message_definitions), once plain and once per extra topic; each is read with open_recording and every frame
// (depth, intrinsics, stamp, T_fixed_camera) compared with the plain MCAP's.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "recording/bag_writer.hpp"
#include "recording/mcap.hpp"
#include "recording/recording.hpp"
#include "tests/recording/bag_fixture.hpp"

namespace stvl::recording {
namespace {

namespace fs = std::filesystem;
using namespace bag_test;
using detail::McapRecord;

constexpr int kFrames = 4;
const std::string kRule(80, '=');

// A topic a replay must list and skip. schema_encoding empty: no schema (MCAP schema id 0; in sqlite3 a
// message_definitions row with encoding "unknown", as rosbag2 writes when it finds no definition).
struct ExtraTopic {
  std::string name, topic, type, schema_encoding, schema, message_encoding, payload;
};

std::string cdr_bytes(std::initializer_list<std::uint8_t> fields) {
  std::string s = {0x00, 0x01, 0x00, 0x00};
  for (auto b : fields) s.push_back(static_cast<char>(b));
  return s;
}

const std::vector<ExtraTopic>& extra_topics() {
  static const std::vector<ExtraTopic> topics = {
      {"service_event", "/add_two_ints/_service_event", "example_interfaces/srv/AddTwoInts_Event", "ros2msg",
       "int64 a\nint64 b\n---\nint64 sum\n", "cdr", cdr_bytes({1, 0, 0, 0, 0, 0, 0, 0, 2, 0, 0, 0, 0, 0, 0, 0})},
      {"action_feedback", "/fibonacci/_action/feedback", "example_interfaces/action/Fibonacci_FeedbackMessage",
       "ros2msg",
       "unique_identifier_msgs/UUID goal_id\nFibonacci_Feedback feedback\n\n" + kRule +
           "\nMSG: unique_identifier_msgs/UUID\n# A universally unique identifier (UUID).\nuint8[16] uuid\n\n" + kRule +
           "\nMSG: example_interfaces/Fibonacci_Feedback\nint32[] sequence\n",
       "cdr", cdr_bytes({7, 7, 7, 7, 7, 7, 7, 7, 7, 7, 7, 7, 7, 7, 7, 7, 1, 0, 0, 0, 5, 0, 0, 0})},
      {"action_status", "/fibonacci/_action/status", "action_msgs/msg/GoalStatusArray", "ros2msg",
       "# An array of goal statuses.\nGoalStatus[] status_list\n\n" + kRule +
           "\nMSG: action_msgs/GoalStatus\n# An action goal can be in one of these states after it is accepted.\n"
           "int8 STATUS_UNKNOWN   = 0\nint8 STATUS_ACCEPTED  = 1\nint8 STATUS_EXECUTING = 2\n"
           "int8 STATUS_CANCELING = 3\nint8 STATUS_SUCCEEDED = 4\nint8 STATUS_CANCELED  = 5\n"
           "int8 STATUS_ABORTED   = 6\n\n# Goal info (contains ID and timestamp).\nGoalInfo goal_info\n\n"
           "# Action goal state-machine status.\nint8 status\n\n" +
           kRule +
           "\nMSG: action_msgs/GoalInfo\n# Goal ID\nunique_identifier_msgs/UUID goal_id\n\n"
           "# Time when the goal was accepted\nbuiltin_interfaces/Time stamp\n\n" +
           kRule + "\nMSG: unique_identifier_msgs/UUID\nuint8[16] uuid\n\n" + kRule +
           "\nMSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n",
       "cdr", cdr_bytes({0, 0, 0, 0})},
      {"json", "/diagnostics_json", "my_msgs/msg/Status", "jsonschema",
       R"({"type": "object", "properties": {"level": {"type": "integer"}}})", "json", R"({"level": 1})"},
      {"ros2idl", "/idl_schema", "my_msgs/msg/IdlOnly", "ros2idl",
       kRule + "\nIDL: my_msgs/msg/IdlOnly\nmodule my_msgs {\n  module msg {\n    struct IdlOnly {\n"
               "      int32 value;\n    };\n  };\n};\n",
       "cdr", cdr_bytes({42, 0, 0, 0})},
      {"protobuf", "/proto_log", "foxglove.Log", "protobuf", std::string("\x0a\x0d\x0a\x09Log.proto\x12\x00", 16),
       "protobuf", std::string("\x08\x01\x12\x02hi", 6)},
      {"no_schema", "/no_schema", "my_msgs/msg/Unknown", "", "", "cdr", cdr_bytes({1, 2, 3, 4})},
      {"bad_schema", "/broken_schema", "my_msgs/msg/Broken", "ros2msg", "%%% not ros2msg\nint32 x\n", "cdr",
       cdr_bytes({1, 0, 0, 0})},
      {"idl_type", "/idl_type", "my_msgs/idl/Thing", "ros2msg", "int32 x\n", "cdr", cdr_bytes({3, 0, 0, 0})},
  };
  return topics;
}

// The plain recording as records: our rosbag2 export read back (schemas, channels, messages in file order).
struct Records {
  std::map<std::uint16_t, detail::McapSchema> schemas;
  std::map<std::uint16_t, detail::McapChannel> channels;
  std::vector<McapRecord> messages;
};

Records read_records(const fs::path& mcap) {
  Records r;
  detail::McapReader reader(mcap.string());
  McapRecord record;
  while (reader.next(record)) {
    if (record.kind == McapRecord::kSchema) r.schemas[record.schema.id] = record.schema;
    if (record.kind == McapRecord::kChannel) r.channels[record.channel.id] = record.channel;
    if (record.kind == McapRecord::kMessage) r.messages.push_back(record);
  }
  return r;
}

std::vector<std::uint8_t> bytes_of(const std::string& s) { return {s.begin(), s.end()}; }

using Extras = std::vector<const ExtraTopic*>;

// The plain records and the extra topics (one message of each after each depth image) as a bare MCAP file.
void write_mcap(const fs::path& path, const Records& plain, const Extras& extras) {
  detail::McapWriter w(path.string(), detail::McapCompression::kZstd, "ros2", "test_ros2_skipped_topics", 4096);
  std::map<std::uint16_t, std::uint16_t> channel_ids;
  std::vector<std::uint16_t> extra_channels;
  for (const ExtraTopic* extra : extras) {
    const std::uint16_t schema =
        extra->schema_encoding.empty() ? 0 : w.add_schema(extra->type, extra->schema_encoding, extra->schema);
    extra_channels.push_back(w.add_channel(schema, extra->topic, extra->message_encoding, {}));
  }
  for (const auto& [id, channel] : plain.channels) {
    const auto& s = plain.schemas.at(channel.schema_id);
    channel_ids[id] = w.add_channel(w.add_schema(s.name, s.encoding, s.data), channel.topic, channel.message_encoding,
                                    channel.metadata);
  }
  for (const auto& m : plain.messages) {
    w.write_message(channel_ids.at(m.channel_id), m.log_time_ns, m.publish_time_ns, m.data);
    if (plain.channels.at(m.channel_id).topic != kDepth) continue;
    for (std::size_t i = 0; i < extras.size(); ++i)
      w.write_message(extra_channels[i], m.log_time_ns, m.log_time_ns, bytes_of(extras[i]->payload));
  }
  w.close();
}

class Db3 {
 public:
  explicit Db3(const fs::path& path) {
    fs::remove(path);
    EXPECT_EQ(sqlite3_open(path.c_str(), &db_), SQLITE_OK);
  }
  ~Db3() { sqlite3_close(db_); }
  void exec(const std::string& sql) {
    char* error = nullptr;
    EXPECT_EQ(sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &error), SQLITE_OK) << (error ? error : "") << sql;
    sqlite3_free(error);
  }
  // INSERT with every value bound (text, or blob when `blobs` says so).
  void insert(const std::string& sql, const std::vector<std::string>& values, std::vector<bool> blobs = {}) {
    sqlite3_stmt* stmt = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(db_, sql.c_str(), -1, &stmt, nullptr), SQLITE_OK) << sql;
    blobs.resize(values.size());
    for (std::size_t i = 0; i < values.size(); ++i) {
      const int col = static_cast<int>(i) + 1;
      if (blobs[i]) sqlite3_bind_blob(stmt, col, values[i].data(), int(values[i].size()), SQLITE_TRANSIENT);
      else sqlite3_bind_text(stmt, col, values[i].data(), int(values[i].size()), SQLITE_TRANSIENT);
    }
    EXPECT_EQ(sqlite3_step(stmt), SQLITE_DONE) << sqlite3_errmsg(db_);
    sqlite3_finalize(stmt);
  }

 private:
  sqlite3* db_ = nullptr;
};

// The same as a rosbag2 sqlite3 file: Jazzy's tables (message_definitions, type_description_hash) or Humble's.
void write_db3(const fs::path& path, const Records& plain, const Extras& extras, bool jazzy) {
  Db3 db(path);
  db.exec("BEGIN;");
  db.exec("CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);");
  db.exec(std::string("INSERT INTO schema VALUES (") + (jazzy ? "4, 'jazzy'" : "3, 'humble'") + ");");
  db.exec(std::string("CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
                      "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL") +
          (jazzy ? ", type_description_hash TEXT NOT NULL);" : ");"));
  db.exec(
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, "
      "data BLOB NOT NULL);");
  if (jazzy)
    db.exec(
        "CREATE TABLE message_definitions(id INTEGER PRIMARY KEY, topic_type TEXT NOT NULL, encoding TEXT NOT "
        "NULL, encoded_message_definition TEXT NOT NULL, type_description_hash TEXT NOT NULL);");
  const std::string topic_sql = std::string("INSERT INTO topics VALUES (?, ?, ?, ?, ?") + (jazzy ? ", '')" : ")");
  const std::string definition_sql = "INSERT INTO message_definitions VALUES (?, ?, ?, ?, '')";
  std::map<std::string, int> definitions;  // one row per type
  auto define = [&](const std::string& type, const std::string& encoding, const std::string& text) {
    if (!jazzy || definitions.count(type)) return;
    const int id = static_cast<int>(definitions.size()) + 1;
    definitions[type] = id;
    db.insert(definition_sql, {std::to_string(id), type, encoding, text});
  };
  const int first_plain = static_cast<int>(extras.size()) + 1;  // topic ids: the extras first
  for (std::size_t i = 0; i < extras.size(); ++i) {
    const ExtraTopic& extra = *extras[i];
    db.insert(topic_sql, {std::to_string(i + 1), extra.topic, extra.type, extra.message_encoding, ""});
    define(extra.type, extra.schema_encoding.empty() ? "unknown" : extra.schema_encoding, extra.schema);
  }
  for (const auto& [id, channel] : plain.channels) {
    const auto& s = plain.schemas.at(channel.schema_id);
    db.insert(topic_sql,
              {std::to_string(id + first_plain), channel.topic, s.name, "cdr",
               channel.metadata.count("offered_qos_profiles") ? channel.metadata.at("offered_qos_profiles") : ""});
    define(s.name, s.encoding, s.data);
  }
  const std::string message_sql = "INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)";
  for (const auto& m : plain.messages) {
    db.insert(
        message_sql,
        {std::to_string(m.channel_id + first_plain), std::to_string(m.log_time_ns), {m.data.begin(), m.data.end()}},
        {false, false, true});
    if (plain.channels.at(m.channel_id).topic != kDepth) continue;
    for (std::size_t i = 0; i < extras.size(); ++i)
      db.insert(message_sql, {std::to_string(i + 1), std::to_string(m.log_time_ns), extras[i]->payload},
                {false, false, true});
  }
  db.exec("COMMIT;");
}

// Every extra topic is in the recording's list, not read, with one message per depth frame; the depth topic is read.
void expect_listed(const fs::path& path, const Extras& extras) {
  const auto recording = open_recording(path.string());
  std::map<std::string, TopicSummary> listed;
  for (const auto& t : recording->info().topics) listed[t.name] = t;
  ASSERT_TRUE(listed.count(kDepth));
  EXPECT_EQ(listed.at(kDepth).use, "depth");
  for (const ExtraTopic* extra : extras) {
    ASSERT_TRUE(listed.count(extra->topic)) << extra->topic;
    EXPECT_EQ(listed.at(extra->topic).use, "") << extra->topic;
    EXPECT_EQ(listed.at(extra->topic).messages, std::uint64_t(kFrames)) << extra->topic;
    EXPECT_EQ(listed.at(extra->topic).message_encoding, extra->message_encoding) << extra->topic;
  }
}

// The plain recording, written once: our export of kFrames frames with tf, and its frames as open_recording reads
// them (the bare MCAP of the folder).
class SkippedTopics : public ::testing::TestWithParam<std::string> {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("stvl_skipped_topics_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    auto bag = make_bag_writer((dir_ / "plain.mcap").string(), BagFormat::kRos2, BagCompression::kNone);
    BagSink::CameraFrames camera;
    camera.T_base_camera_link = kBaseCameraLink, camera.T_camera_link_optical = optical_on_link();
    bag->write_tf_static({camera});
    for (int k = 0; k < kFrames; ++k) {
      const double t_s = 0.1 * k;
      bag->write_tf(t_s, map_odom(k), odom_base(k));
      bag->write_camera_info(t_s, intrinsics());
      bag->write_depth_image(t_s, intrinsics(), pattern_mm(k));
    }
    bag->close();
    plain_mcap_ = dir_ / "plain" / "plain_0.mcap";
    records_ = new Records(read_records(plain_mcap_));
    expected_ = new std::vector<RecordedFrame>(frames_of(plain_mcap_));
  }
  static void TearDownTestSuite() {
    delete records_, delete expected_;
    fs::remove_all(dir_);
  }
  // "plain": none; "all": every one; else the one so named.
  static Extras extras(const std::string& name) {
    Extras chosen;
    for (const auto& e : extra_topics())
      if (name == "all" || e.name == name) chosen.push_back(&e);
    return chosen;
  }
  static inline fs::path dir_, plain_mcap_;
  static inline Records* records_ = nullptr;
  static inline std::vector<RecordedFrame>* expected_ = nullptr;
};

TEST_P(SkippedTopics, McapReplaysAsThePlainOne) {
  ASSERT_EQ(expected_->size(), std::size_t(kFrames));  // the reference itself: every frame, as written
  for (int k = 0; k < kFrames; ++k) expect_depth_mm((*expected_)[k].depth, pattern_mm(k));
  const fs::path path = dir_ / (GetParam() + ".mcap");
  write_mcap(path, *records_, extras(GetParam()));
  expect_same_frames(frames_of(path), *expected_);
  testing::internal::CaptureStderr();  // the warning about the schema that does not parse
  expect_listed(path, extras(GetParam()));
  testing::internal::GetCapturedStderr();
}

TEST_P(SkippedTopics, JazzyDb3ReplaysAsThePlainOne) {
  const fs::path path = dir_ / (GetParam() + "_jazzy.db3");
  write_db3(path, *records_, extras(GetParam()), true);
  expect_same_frames(frames_of(path), *expected_);
  testing::internal::CaptureStderr();  // the warning about the schema that does not parse
  expect_listed(path, extras(GetParam()));
  testing::internal::GetCapturedStderr();
}

TEST_P(SkippedTopics, HumbleDb3ReplaysAsThePlainOne) {
  const fs::path path = dir_ / (GetParam() + "_humble.db3");
  write_db3(path, *records_, extras(GetParam()), false);
  expect_same_frames(frames_of(path), *expected_);
  testing::internal::CaptureStderr();  // the warning about the schema that does not parse
  expect_listed(path, extras(GetParam()));
  testing::internal::GetCapturedStderr();
}

std::vector<std::string> case_names() {
  std::vector<std::string> names = {"plain", "all"};
  for (const auto& e : extra_topics()) names.push_back(e.name);
  return names;
}

INSTANTIATE_TEST_SUITE_P(Ros2, SkippedTopics, ::testing::ValuesIn(case_names()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace
}  // namespace stvl::recording

// The navigation drive in both export formats, as nav2 publishes it: nav_msgs/Path (/plan), geometry_msgs/Twist
// (/cmd_vel) and nav_msgs/OccupancyGrid on any topic (/local_costmap/costmap, /global_costmap/costmap). ROS 1 read
// back with rosbag, ROS 2 with our MCAP reader and CDR decoded field by field.
#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/Path.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "recording/bag_writer.hpp"
#include "recording/cdr.hpp"
#include "recording/mcap.hpp"
#include "recording/ros2_msgs.hpp"
#include "recording/ros2msg.hpp"
#include "tests/support/command.hpp"

namespace stvl::recording {
namespace {

namespace fs = std::filesystem;

constexpr double kPlan_s = 0.25, kCmd_s = 0.3, kCostmap_s = 0.5;
constexpr double kV_mps = 0.42, kOmega_radps = -0.35;
// Yaws on both sides of +-pi: the quaternion must be the rotation about z, whatever its sign convention.
const std::vector<Eigen::Vector3d> kPoses = {{0.0, 0.0, 0.0}, {1.5, -0.25, 0.7}, {2.0, 1.0, 3.1}, {-3.0, 4.5, -2.9}};

mapping::Costmap2D test_costmap() {
  mapping::Costmap2D c;
  c.width = 3, c.height = 2, c.resolution_m = 0.05, c.origin_m = {-1.25, 2.5};
  c.cells = {mapping::kCostFree, 1, 128, 253, mapping::kCostLethal, mapping::kCostUnknown};
  return c;
}
const std::vector<std::int8_t> kOccupancy = {0, 1, 1 + 97 * 127 / 251, 99, 100, -1};

// The stamp of t_s: t_s + kBagTimeOffset_s in nanoseconds.
std::uint64_t stamp_ns(double t_s) { return std::llround((t_s + kBagTimeOffset_s) * 1e9); }

void write_nav(BagSink& sink) {
  sink.write_path(kPlanTopic, kPlan_s, kPoses);
  sink.write_path(kPlanTopic, kPlan_s + 0.1, {});  // no path: nav2 publishes one without poses
  sink.write_twist(kCmdVelTopic, kCmd_s, kV_mps, kOmega_radps);
  sink.write_costmap_on(kLocalCostmapTopic, kCostmap_s, test_costmap());
  sink.write_costmap_on(kGlobalCostmapTopic, kCostmap_s, test_costmap());
  sink.write_costmap(kCostmap_s, test_costmap());
}

// The pose's orientation is the rotation by yaw about z.
void expect_yaw(double qx, double qy, double qz, double qw, double yaw, const std::string& what) {
  EXPECT_NEAR(qx * qx + qy * qy + qz * qz + qw * qw, 1.0, 1e-12) << what;
  EXPECT_EQ(qx, 0.0) << what;
  EXPECT_EQ(qy, 0.0) << what;
  EXPECT_NEAR(2.0 * std::atan2(qz, qw), yaw, 1e-12) << what;
}

TEST(NavTopicsRos1, PathTwistAndCostmapsReadBackWithRosbag) {
  const test::TempDir dir("nav_topics_ros1");
  const fs::path path = dir.path() / "nav.bag";
  auto sink = make_bag_writer(path.string(), BagFormat::kRos1, BagCompression::kLz4);
  write_nav(*sink);
  sink->close();

  rosbag::Bag bag(path.string(), rosbag::bagmode::Read);
  std::map<std::string, std::string> types;
  std::map<std::string, int> counts;
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    types[m.getTopic()] = m.getDataType();
    ++counts[m.getTopic()];
  }
  const std::map<std::string, std::string> expected_types = {{"/plan", "nav_msgs/Path"},
                                                             {"/cmd_vel", "geometry_msgs/Twist"},
                                                             {"/local_costmap/costmap", "nav_msgs/OccupancyGrid"},
                                                             {"/global_costmap/costmap", "nav_msgs/OccupancyGrid"},
                                                             {"/stvl/costmap", "nav_msgs/OccupancyGrid"}};
  EXPECT_EQ(types, expected_types);
  EXPECT_EQ(counts["/plan"], 2);

  std::vector<nav_msgs::Path> paths;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/plan"))) {
    const auto msg = m.instantiate<nav_msgs::Path>();
    ASSERT_TRUE(msg);
    EXPECT_EQ(m.getTime().toNSec(), msg->header.stamp.toNSec());
    paths.push_back(*msg);
  }
  ASSERT_EQ(paths.size(), 2u);
  const nav_msgs::Path& plan = paths[0];
  EXPECT_EQ(plan.header.frame_id, kMapFrame);
  EXPECT_EQ(plan.header.stamp.toNSec(), stamp_ns(kPlan_s));
  ASSERT_EQ(plan.poses.size(), kPoses.size());
  for (std::size_t i = 0; i < kPoses.size(); ++i) {
    const geometry_msgs::PoseStamped& p = plan.poses[i];
    const std::string what = "pose " + std::to_string(i);
    EXPECT_EQ(p.header.frame_id, kMapFrame) << what;
    EXPECT_EQ(p.header.stamp, plan.header.stamp) << what;
    EXPECT_EQ(p.header.seq, plan.header.seq) << what;
    EXPECT_EQ(p.pose.position.x, kPoses[i].x()) << what;
    EXPECT_EQ(p.pose.position.y, kPoses[i].y()) << what;
    EXPECT_EQ(p.pose.position.z, 0.0) << what;
    const auto& q = p.pose.orientation;
    expect_yaw(q.x, q.y, q.z, q.w, kPoses[i].z(), what);
  }
  EXPECT_TRUE(paths[1].poses.empty());
  EXPECT_EQ(paths[1].header.frame_id, kMapFrame);

  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/cmd_vel"))) {
    const auto twist = m.instantiate<geometry_msgs::Twist>();
    ASSERT_TRUE(twist);
    EXPECT_EQ(m.getTime().toNSec(), stamp_ns(kCmd_s));
    EXPECT_EQ(twist->linear.x, kV_mps);
    EXPECT_EQ(twist->angular.z, kOmega_radps);
    EXPECT_EQ(twist->linear.y, 0.0);
    EXPECT_EQ(twist->linear.z, 0.0);
    EXPECT_EQ(twist->angular.x, 0.0);
    EXPECT_EQ(twist->angular.y, 0.0);
  }

  for (const char* topic : {kLocalCostmapTopic, kGlobalCostmapTopic, kStvlCostmapTopic}) {
    int n = 0;
    for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(topic))) {
      const auto grid = m.instantiate<nav_msgs::OccupancyGrid>();
      ASSERT_TRUE(grid) << topic;
      ++n;
      EXPECT_EQ(grid->header.frame_id, kMapFrame) << topic;
      EXPECT_EQ(grid->header.stamp.toNSec(), stamp_ns(kCostmap_s)) << topic;
      EXPECT_EQ(m.getTime(), grid->header.stamp) << topic;
      EXPECT_EQ(grid->info.width, 3u) << topic;
      EXPECT_EQ(grid->info.height, 2u) << topic;
      EXPECT_FLOAT_EQ(grid->info.resolution, 0.05f) << topic;
      EXPECT_EQ(grid->info.origin.position.x, -1.25) << topic;
      EXPECT_EQ(grid->info.origin.position.y, 2.5) << topic;
      EXPECT_EQ(grid->info.origin.orientation.w, 1.0) << topic;
      EXPECT_EQ(grid->data, kOccupancy) << topic;
    }
    EXPECT_EQ(n, 1) << topic;
  }
}

// Our rosbag2 export read back: schemas, channels and messages by topic.
struct Ros2Bag {
  std::map<std::uint16_t, detail::McapSchema> schemas;
  std::map<std::string, detail::McapChannel> channels;
  std::map<std::string, std::vector<detail::McapRecord>> messages;
};

Ros2Bag read_ros2(const fs::path& mcap) {
  Ros2Bag bag;
  std::map<std::uint16_t, std::string> topics;
  detail::McapReader reader(mcap.string());
  detail::McapRecord r;
  while (reader.next(r)) {
    if (r.kind == detail::McapRecord::kSchema) bag.schemas[r.schema.id] = r.schema;
    if (r.kind == detail::McapRecord::kChannel)
      bag.channels[r.channel.topic] = r.channel, topics[r.channel.id] = r.channel.topic;
    if (r.kind == detail::McapRecord::kMessage) bag.messages[topics.at(r.channel_id)].push_back(r);
  }
  return bag;
}

std::uint64_t get_stamp_ns(detail::CdrReader& r) {
  const auto sec = r.get<std::int32_t>();
  const auto nanosec = r.get<std::uint32_t>();
  return std::uint64_t(sec) * 1000000000ull + nanosec;
}

TEST(NavTopicsRos2, PathTwistAndCostmapsDecodeFromTheMcapFile) {
  const test::TempDir dir("nav_topics_ros2");
  auto sink = make_bag_writer((dir.path() / "nav").string(), BagFormat::kRos2, BagCompression::kZstd);
  write_nav(*sink);
  sink->close();
  const Ros2Bag bag = read_ros2(dir.path() / "nav" / "nav_0.mcap");

  const std::map<std::string, std::string> expected_types = {{"/plan", "nav_msgs/msg/Path"},
                                                             {"/cmd_vel", "geometry_msgs/msg/Twist"},
                                                             {"/local_costmap/costmap", "nav_msgs/msg/OccupancyGrid"},
                                                             {"/global_costmap/costmap", "nav_msgs/msg/OccupancyGrid"},
                                                             {"/stvl/costmap", "nav_msgs/msg/OccupancyGrid"}};
  ASSERT_EQ(bag.channels.size(), expected_types.size());
  for (const auto& [topic, type] : expected_types) {
    ASSERT_TRUE(bag.channels.count(topic)) << topic;
    const detail::McapChannel& c = bag.channels.at(topic);
    EXPECT_EQ(c.message_encoding, "cdr") << topic;
    const detail::McapSchema& s = bag.schemas.at(c.schema_id);
    EXPECT_EQ(s.name, type) << topic;
    EXPECT_EQ(s.encoding, "ros2msg") << topic;
    EXPECT_EQ(s.data, detail::ros2_definition(type)) << topic;
    EXPECT_NO_THROW(detail::check_ros2_schema(type, s.data, topic));
    EXPECT_TRUE(c.metadata.count("topic_type_hash")) << topic;
  }
  // The schemas carry every type they use, as rosbag2 embeds them.
  const detail::MsgSchema path_schema =
      detail::parse_ros2msg("nav_msgs/msg/Path", bag.schemas.at(bag.channels.at("/plan").schema_id).data);
  for (const char* used : {"std_msgs/msg/Header", "builtin_interfaces/msg/Time", "geometry_msgs/msg/PoseStamped",
                           "geometry_msgs/msg/Pose", "geometry_msgs/msg/Point", "geometry_msgs/msg/Quaternion"})
    EXPECT_TRUE(path_schema.find(used)) << used;
  const detail::MsgSchema twist_schema =
      detail::parse_ros2msg("geometry_msgs/msg/Twist", bag.schemas.at(bag.channels.at("/cmd_vel").schema_id).data);
  EXPECT_TRUE(twist_schema.find("geometry_msgs/msg/Vector3"));

  // nav_msgs/Path: header, then the poses, each a header and 7 float64.
  ASSERT_EQ(bag.messages.at("/plan").size(), 2u);
  const detail::McapRecord& plan = bag.messages.at("/plan")[0];
  EXPECT_EQ(plan.log_time_ns, stamp_ns(kPlan_s));
  EXPECT_EQ(plan.publish_time_ns, stamp_ns(kPlan_s));
  detail::CdrReader r(plan.data.data(), plan.data.size(), "/plan");
  EXPECT_EQ(get_stamp_ns(r), stamp_ns(kPlan_s));
  EXPECT_EQ(r.get_string(), kMapFrame);
  ASSERT_EQ(r.get_count(8), kPoses.size());
  for (std::size_t i = 0; i < kPoses.size(); ++i) {
    const std::string what = "pose " + std::to_string(i);
    EXPECT_EQ(get_stamp_ns(r), stamp_ns(kPlan_s)) << what;
    EXPECT_EQ(r.get_string(), kMapFrame) << what;
    double p[7];
    r.get_array(p, 7);
    EXPECT_EQ(p[0], kPoses[i].x()) << what;
    EXPECT_EQ(p[1], kPoses[i].y()) << what;
    EXPECT_EQ(p[2], 0.0) << what;
    expect_yaw(p[3], p[4], p[5], p[6], kPoses[i].z(), what);
  }
  EXPECT_THROW(r.get<std::uint8_t>(), std::invalid_argument);  // nothing after the poses
  const detail::McapRecord& empty = bag.messages.at("/plan")[1];
  detail::CdrReader e(empty.data.data(), empty.data.size(), "/plan");
  EXPECT_EQ(get_stamp_ns(e), stamp_ns(kPlan_s + 0.1));
  EXPECT_EQ(e.get_string(), kMapFrame);
  EXPECT_EQ(e.get<std::uint32_t>(), 0u);

  // geometry_msgs/Twist: linear x y z, angular x y z; no header.
  ASSERT_EQ(bag.messages.at("/cmd_vel").size(), 1u);
  const detail::McapRecord& cmd = bag.messages.at("/cmd_vel")[0];
  EXPECT_EQ(cmd.log_time_ns, stamp_ns(kCmd_s));
  EXPECT_EQ(cmd.data.size(), 4u + 6 * 8);
  detail::CdrReader t(cmd.data.data(), cmd.data.size(), "/cmd_vel");
  double twist[6];
  t.get_array(twist, 6);
  EXPECT_EQ(twist[0], kV_mps);
  EXPECT_EQ(twist[5], kOmega_radps);
  for (int i = 1; i < 5; ++i) EXPECT_EQ(twist[i], 0.0) << i;

  // nav_msgs/OccupancyGrid: header, MapMetaData (load time, resolution, width, height, origin), int8[] data.
  for (const char* topic : {kLocalCostmapTopic, kGlobalCostmapTopic, kStvlCostmapTopic}) {
    ASSERT_EQ(bag.messages.at(topic).size(), 1u) << topic;
    const detail::McapRecord& m = bag.messages.at(topic)[0];
    EXPECT_EQ(m.log_time_ns, stamp_ns(kCostmap_s)) << topic;
    detail::CdrReader g(m.data.data(), m.data.size(), topic);
    EXPECT_EQ(get_stamp_ns(g), stamp_ns(kCostmap_s)) << topic;
    EXPECT_EQ(g.get_string(), kMapFrame) << topic;
    EXPECT_EQ(get_stamp_ns(g), stamp_ns(kCostmap_s)) << topic;
    EXPECT_FLOAT_EQ(g.get<float>(), 0.05f) << topic;
    EXPECT_EQ(g.get<std::uint32_t>(), 3u) << topic;
    EXPECT_EQ(g.get<std::uint32_t>(), 2u) << topic;
    double origin[7];
    g.get_array(origin, 7);
    EXPECT_EQ(origin[0], -1.25) << topic;
    EXPECT_EQ(origin[1], 2.5) << topic;
    EXPECT_EQ(origin[6], 1.0) << topic;
    const auto [data, size] = g.get_bytes();
    EXPECT_EQ(std::vector<std::int8_t>(data, data + size), kOccupancy) << topic;
  }
}

// @mcap/core reads the file and @foxglove/rosmsg2-serialization decodes every message from the schemas it carries
// (mcap_js/verify_mcap.cjs, installed by recording.ros2_interop; skipped without it).
TEST(NavTopicsRos2, ReferenceImplementationDecodesThem) {
  const fs::path modules = STVL_MCAP_JS_MODULES;
  if (!fs::is_directory(modules / "@mcap" / "core")) GTEST_SKIP() << modules << " has no @mcap/core yet";
  if (test::run_shell("node --version").exit_code != 0) GTEST_SKIP() << "node is not installed";
  const test::TempDir dir("nav_topics_js");
  auto sink = make_bag_writer((dir.path() / "nav").string(), BagFormat::kRos2, BagCompression::kLz4);
  write_nav(*sink);
  sink->close();
  const std::string script = std::string(STVL_SOURCE_DIR) + "/tests/recording/mcap_js/verify_mcap.cjs";
  const test::Outcome out =
      test::run_shell("NODE_PATH=" + test::quoted(modules.string()) + " node " + test::quoted(script) + " " +
                      test::quoted((dir.path() / "nav" / "nav_0.mcap").string()));
  ASSERT_EQ(out.exit_code, 0) << out.output;
  const YAML::Node topics = YAML::Load(out.output)["topics"];  // JSON is YAML
  EXPECT_EQ(topics["/plan"]["type"].as<std::string>(), "nav_msgs/msg/Path");
  EXPECT_EQ(topics["/plan"]["count"].as<int>(), 2);
  const YAML::Node plan = topics["/plan"]["first"];
  EXPECT_EQ(plan["frame_id"].as<std::string>(), kMapFrame);
  ASSERT_EQ(plan["poses"].size(), kPoses.size());
  for (std::size_t i = 0; i < kPoses.size(); ++i) {
    const YAML::Node p = plan["poses"][i];
    EXPECT_EQ(p[0].as<double>(), kPoses[i].x()) << i;
    EXPECT_EQ(p[1].as<double>(), kPoses[i].y()) << i;
    EXPECT_EQ(p[2].as<double>(), 0.0) << i;
    expect_yaw(p[3].as<double>(), p[4].as<double>(), p[5].as<double>(), p[6].as<double>(), kPoses[i].z(),
               "pose " + std::to_string(i));
  }
  EXPECT_EQ(topics["/cmd_vel"]["type"].as<std::string>(), "geometry_msgs/msg/Twist");
  const YAML::Node twist = topics["/cmd_vel"]["first"];
  EXPECT_EQ(twist["linear"][0].as<double>(), kV_mps);
  EXPECT_EQ(twist["angular"][2].as<double>(), kOmega_radps);
  for (const char* topic : {kLocalCostmapTopic, kGlobalCostmapTopic, kStvlCostmapTopic}) {
    EXPECT_EQ(topics[topic]["type"].as<std::string>(), "nav_msgs/msg/OccupancyGrid") << topic;
    const YAML::Node grid = topics[topic]["first"];
    EXPECT_EQ(grid["frame_id"].as<std::string>(), kMapFrame) << topic;
    EXPECT_EQ(grid["width"].as<int>(), 3) << topic;
    EXPECT_EQ(grid["height"].as<int>(), 2) << topic;
    std::vector<std::int8_t> data;
    for (const auto& v : grid["data"]) data.push_back(static_cast<std::int8_t>(v.as<int>()));
    EXPECT_EQ(data, kOccupancy) << topic;
  }
}

TEST(NavTopics, BothFormatsRejectBadInput) {
  const test::TempDir dir("nav_topics_bad");
  for (const BagFormat format : {BagFormat::kRos1, BagFormat::kRos2}) {
    auto sink = make_bag_writer((dir.path() / (format == BagFormat::kRos1 ? "bad.bag" : "bad")).string(), format,
                                BagCompression::kNone);
    const double inf = std::numeric_limits<double>::infinity();
    EXPECT_THROW(sink->write_path("plan", 0.0, kPoses), std::invalid_argument);
    EXPECT_THROW(sink->write_path(kPlanTopic, -1.0, kPoses), std::invalid_argument);
    EXPECT_THROW(sink->write_path(kPlanTopic, 0.0, {{0.0, inf, 0.0}}), std::invalid_argument);
    EXPECT_THROW(sink->write_twist("", 0.0, 0.1, 0.1), std::invalid_argument);
    EXPECT_THROW(sink->write_twist(kCmdVelTopic, 0.0, std::nan(""), 0.1), std::invalid_argument);
    EXPECT_THROW(sink->write_costmap_on("costmap", 0.0, test_costmap()), std::invalid_argument);
    mapping::Costmap2D wrong = test_costmap();
    wrong.cells.pop_back();
    EXPECT_THROW(sink->write_costmap_on(kLocalCostmapTopic, 0.0, wrong), std::invalid_argument);
    sink->close();
    EXPECT_THROW(sink->write_twist(kCmdVelTopic, 1.0, 0.1, 0.1), std::runtime_error);
  }
}

}  // namespace
}  // namespace stvl::recording

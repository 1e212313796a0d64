#include "recording/bag_writer.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/support/command.hpp"

namespace stvl::recording {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 16;
constexpr int kHeight = 12;
constexpr double kFx = 12.5;
constexpr double kFy = 11.0;
constexpr double kCx = 7.5;
constexpr double kCy = 5.25;
constexpr int kFrames = 4;
constexpr double kFramePeriod_s = 0.1;

sensors::CameraIntrinsics intrinsics(double cx_px = kCx) {
  sensors::CameraIntrinsics k;
  k.width = kWidth, k.height = kHeight, k.fx = kFx, k.fy = kFy, k.cx = cx_px, k.cy = kCy;
  return k;
}

const std::string kChecker = std::string(STVL_SOURCE_DIR) + "/tests/run/check_bag.py";

// Known pattern with invalid (0) pixels; frame k shifts it so the images differ.
std::vector<std::uint16_t> depth_pattern_mm(int frame) {
  std::vector<std::uint16_t> depth(kWidth * kHeight);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      const bool invalid = (u + 2 * v + frame) % 7 == 0;
      depth[v * kWidth + u] = invalid ? 0 : static_cast<std::uint16_t>(400 + 37 * u + 101 * v + 250 * frame);
    }
  }
  return depth;
}

Eigen::Matrix3Xf depth_to_points_C(const std::vector<std::uint16_t>& depth_mm) {
  Eigen::Matrix3Xf points(3, depth_mm.size());
  int n = 0;
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      const std::uint16_t d = depth_mm[v * kWidth + u];
      if (d == 0) continue;
      const double z = d * 1e-3;
      points.col(n++) = Eigen::Vector3d((u - kCx) * z / kFx, (v - kCy) * z / kFy, z).cast<float>();
    }
  }
  points.conservativeResize(3, n);
  return points;
}

Eigen::Isometry3d pose_xy_yaw(double x, double y, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, 0.0);
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

// Writes kFrames frames of every topic; the camera cloud is the depth image reprojected with the camera info.
void write_run(BagWriter& writer) {
  Eigen::Isometry3d T_base_camera_link = Eigen::Isometry3d::Identity();
  T_base_camera_link.translation() = Eigen::Vector3d(0.2, 0.0, 0.3);
  Eigen::Isometry3d T_camera_link_optical = Eigen::Isometry3d::Identity();
  T_camera_link_optical.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  writer.write_tf_static(T_base_camera_link, T_camera_link_optical);

  Eigen::Matrix3Xf occupancy_M(3, 3);
  occupancy_M << 1.0f, 1.0f, 1.05f, 0.0f, 0.05f, 0.0f, 0.025f, 0.025f, 0.025f;
  writer.write_points("/ground_truth/occupancy", 0.0, kMapFrame, occupancy_M, /*latched=*/true);

  for (int k = 0; k < kFrames; ++k) {
    const double t_s = k * kFramePeriod_s;  // the first frame is at t = 0
    const Eigen::Isometry3d T_odom_base = pose_xy_yaw(0.05 * k, 0.0, 0.01 * k);
    writer.write_clock(t_s);
    writer.write_tf(t_s, pose_xy_yaw(0.001 * k, 0.0, 0.0), T_odom_base);
    writer.write_odometry(t_s, T_odom_base, 0.5, 0.1);
    writer.write_ground_truth_pose(t_s, pose_xy_yaw(0.05 * k + 0.001 * k, 0.0, 0.01 * k));
    const std::vector<std::uint16_t> depth = depth_pattern_mm(k);
    writer.write_depth_image(t_s, intrinsics(), depth);
    writer.write_camera_info(t_s, intrinsics());
    const Eigen::Matrix3Xf points_C = depth_to_points_C(depth);
    writer.write_points("/camera/depth/points", t_s, kCameraOpticalFrame, points_C);
    writer.write_points("/stvl/filtered_points", t_s, kMapFrame, points_C.leftCols(points_C.cols() / 2));
    writer.write_points("/stvl/voxel_grid", t_s, kMapFrame, points_C.leftCols(5));
    mapping::Costmap2D costmap;
    costmap.width = 6, costmap.height = 4, costmap.resolution_m = 0.05, costmap.origin_m = {-0.1, -0.1};
    costmap.cells.assign(6 * 4, mapping::kCostFree);
    costmap.cells[k] = mapping::kCostLethal;
    costmap.cells[23] = mapping::kCostUnknown;
    writer.write_costmap(t_s, costmap);
    // The navigation drive as nav2 publishes it.
    writer.write_costmap_on(kLocalCostmapTopic, t_s, costmap);
    writer.write_costmap_on(kGlobalCostmapTopic, t_s, costmap);
    writer.write_path(kPlanTopic, t_s, {{0.05 * k, 0.0, 0.01 * k}, {1.0, 0.5, 1.2}});
    writer.write_twist(kCmdVelTopic, t_s, 0.5, 0.1);
  }
}

std::string expectations_json(BagCompression compression, int frame_count) {
  struct Topic {
    const char* name;
    const char* type;
    int count;
    const char* frame;
    bool latched;
  };
  const Topic topics[] = {
      {"/clock", "rosgraph_msgs/Clock", frame_count, nullptr, false},
      {"/tf", "tf2_msgs/TFMessage", frame_count, nullptr, false},
      {"/tf_static", "tf2_msgs/TFMessage", 1, nullptr, true},
      {"/odom", "nav_msgs/Odometry", frame_count, kOdomFrame, false},
      {"/ground_truth/pose", "geometry_msgs/PoseStamped", frame_count, kMapFrame, false},
      {"/camera/depth/image_rect_raw", "sensor_msgs/Image", frame_count, kCameraOpticalFrame, false},
      {"/camera/depth/camera_info", "sensor_msgs/CameraInfo", frame_count, kCameraOpticalFrame, false},
      {"/camera/depth/points", "sensor_msgs/PointCloud2", frame_count, kCameraOpticalFrame, false},
      {"/stvl/filtered_points", "sensor_msgs/PointCloud2", frame_count, kMapFrame, false},
      {"/stvl/voxel_grid", "sensor_msgs/PointCloud2", frame_count, kMapFrame, false},
      {"/stvl/costmap", "nav_msgs/OccupancyGrid", frame_count, kMapFrame, false},
      {"/local_costmap/costmap", "nav_msgs/OccupancyGrid", frame_count, kMapFrame, false},
      {"/global_costmap/costmap", "nav_msgs/OccupancyGrid", frame_count, kMapFrame, false},
      {"/plan", "nav_msgs/Path", frame_count, kMapFrame, false},
      {"/cmd_vel", "geometry_msgs/Twist", frame_count, nullptr, false},
      {"/ground_truth/occupancy", "sensor_msgs/PointCloud2", 1, kMapFrame, true},
  };
  std::ostringstream json;
  json << "{\n  \"compression\": \"" << to_string(compression) << "\",\n  \"only_listed_topics\": true,\n";
  json << "  \"topics\": {\n";
  bool first = true;
  for (const Topic& t : topics) {
    json << (first ? "" : ",\n") << "    \"" << t.name << "\": {\"type\": \"" << t.type << "\", \"count\": " << t.count
         << ", \"latched\": " << (t.latched ? "true" : "false");
    if (t.frame) json << ", \"frame_id\": \"" << t.frame << "\"";
    json << "}";
    first = false;
  }
  json << "\n  },\n";
  json << "  \"tf_edges\": [[\"map\", \"odom\"], [\"odom\", \"base_link\"], [\"base_link\", \"camera_link\"], "
          "[\"camera_link\", \"camera_depth_optical_frame\"]],\n";
  json << "  \"depth\": {\"topic\": \"/camera/depth/image_rect_raw\", \"values_mm\": [";
  for (int k = 0; k < frame_count; ++k) {
    json << (k ? ", " : "") << "[";
    const std::vector<std::uint16_t> depth = depth_pattern_mm(k);
    for (std::size_t i = 0; i < depth.size(); ++i) json << (i ? "," : "") << depth[i];
    json << "]";
  }
  json << "]},\n";
  json << "  \"reprojection\": {\"tolerance_m\": 1e-5, \"tolerance_rel\": 1e-6, \"tolerance_px\": 1e-3, "
          "\"min_fraction\": 1.0, \"complete\": true, \"max_frames\": 0}\n}\n";
  return json.str();
}

test::Outcome run_checker(const fs::path& bag, const std::string& json, const fs::path& dir) {
  const fs::path expect = dir / "expect.json";
  std::ofstream(expect) << json;
  return test::run_shell("/usr/bin/python3 " + test::quoted(kChecker) + " " + test::quoted(bag.string()) + " " +
                         test::quoted(expect.string()));
}

class BagWriterCompressionTest : public ::testing::TestWithParam<BagCompression> {};

TEST_P(BagWriterCompressionTest, WholeApiPassesTheChecker) {
  const BagCompression compression = GetParam();
  const test::TempDir dir("bag_api_" + to_string(compression));
  const fs::path bag = dir.path() / "run.bag";
  {
    BagWriter writer(bag.string(), compression);
    write_run(writer);
    EXPECT_TRUE(fs::exists(bag.string() + ".active"));
    EXPECT_FALSE(fs::exists(bag));
    writer.close();
    EXPECT_EQ(writer.bytes_written(), fs::file_size(bag));
  }
  EXPECT_FALSE(fs::exists(bag.string() + ".active"));
  ASSERT_TRUE(fs::exists(bag));

  const test::Outcome result = run_checker(bag, expectations_json(compression, kFrames), dir.path());
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("0 failed"), std::string::npos) << result.output;
}

INSTANTIATE_TEST_SUITE_P(AllCompressions, BagWriterCompressionTest,
                         ::testing::Values(BagCompression::kNone, BagCompression::kBz2, BagCompression::kLz4),
                         [](const auto& info) { return to_string(info.param); });

TEST(BagWriterTest, CheckerFailsOnWrongExpectations) {
  const test::TempDir dir("bag_wrong");
  const fs::path bag = dir.path() / "run.bag";
  {
    BagWriter writer(bag.string(), BagCompression::kLz4);
    write_run(writer);
    writer.close();
  }
  // One frame fewer than written: counts and depth values disagree with the bag.
  const test::Outcome result = run_checker(bag, expectations_json(BagCompression::kLz4, kFrames - 1), dir.path());
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_NE(result.output.find("FAIL: /clock: 4 messages, expected 3"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("FAIL: depth: 4 images, expected 3"), std::string::npos) << result.output;
}

TEST(BagWriterTest, CheckerCatchesACloudInconsistentWithTheCameraInfo) {
  const test::TempDir dir("bag_inconsistent");
  const fs::path bag = dir.path() / "run.bag";
  {
    BagWriter writer(bag.string(), BagCompression::kNone);
    const std::vector<std::uint16_t> depth = depth_pattern_mm(0);
    writer.write_depth_image(0.0, intrinsics(), depth);
    writer.write_camera_info(0.0, intrinsics(kCx + 0.5));  // half a pixel off
    writer.write_points("/camera/depth/points", 0.0, kCameraOpticalFrame, depth_to_points_C(depth));
    writer.close();
  }
  const test::Outcome result = run_checker(bag, "{}", dir.path());
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_NE(result.output.find("points match the depth image"), std::string::npos) << result.output;
}

TEST(BagWriterTest, DestroyedWithoutCloseLeavesOnlyTheActiveFile) {
  const test::TempDir dir("bag_interrupted");
  const fs::path bag = dir.path() / "run.bag";
  try {
    BagWriter writer(bag.string(), BagCompression::kLz4);
    writer.write_clock(0.0);
    writer.write_depth_image(0.1, intrinsics(), std::vector<std::uint16_t>(3));  // wrong size: throws
    FAIL() << "write_depth_image accepted a wrong-sized image";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("depth image has 3 values"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::exists(bag.string() + ".active"));
  EXPECT_FALSE(fs::exists(bag));
}

TEST(BagWriterTest, UnwritablePathThrowsAClearError) {
  const std::string path = "/nonexistent_stvl_dir/run.bag";
  try {
    BagWriter writer(path, BagCompression::kNone);
    FAIL() << "opened " << path;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot create bag '" + path + ".active'"), std::string::npos) << e.what();
  }
}

TEST(BagWriterTest, CostsBecomeOccupancyAsNav2PublishesThem) {
  mapping::Costmap2D costmap;
  costmap.width = 6, costmap.height = 1;
  costmap.cells = {mapping::kCostFree, 1, 128, 252, 253, mapping::kCostLethal};
  EXPECT_EQ(occupancy_values(costmap), (std::vector<std::int8_t>{0, 1, 1 + 97 * 127 / 251, 98, 99, 100}));
  costmap.width = 1;
  costmap.cells = {mapping::kCostUnknown};
  EXPECT_EQ(occupancy_values(costmap), (std::vector<std::int8_t>{-1}));
}

TEST(BagWriterTest, RejectsBadInput) {
  const test::TempDir dir("bag_bad_input");
  BagWriter writer((dir.path() / "run.bag").string(), BagCompression::kNone);
  EXPECT_THROW(writer.write_clock(-0.5), std::invalid_argument);
  EXPECT_THROW(writer.write_clock(std::nan("")), std::invalid_argument);
  sensors::CameraIntrinsics no_focal = intrinsics();
  no_focal.fx = 0.0;
  EXPECT_THROW(writer.write_camera_info(0.0, no_focal), std::invalid_argument);
  EXPECT_THROW(writer.write_points("no_slash", 0.0, kMapFrame, Eigen::Matrix3Xf(3, 1)), std::invalid_argument);
  mapping::Costmap2D wrong_size;
  wrong_size.width = wrong_size.height = 2;
  wrong_size.cells.assign(3, mapping::kCostFree);
  EXPECT_THROW(writer.write_costmap(0.0, wrong_size), std::invalid_argument);
  mapping::Costmap2D no_resolution;
  no_resolution.width = no_resolution.height = 1;
  no_resolution.cells.assign(1, mapping::kCostFree);
  no_resolution.resolution_m = 0.0;
  EXPECT_THROW(writer.write_costmap(0.0, no_resolution), std::invalid_argument);
  Eigen::Isometry3d not_finite = Eigen::Isometry3d::Identity();
  not_finite.translation().x() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(writer.write_ground_truth_pose(0.0, not_finite), std::invalid_argument);
  writer.close();
  EXPECT_THROW(writer.write_clock(1.0), std::runtime_error);
  EXPECT_THROW(writer.close(), std::runtime_error);
}

TEST(BagWriterTest, ParsesCompressionNames) {
  EXPECT_EQ(parse_bag_compression("none"), BagCompression::kNone);
  EXPECT_EQ(parse_bag_compression("bz2"), BagCompression::kBz2);
  EXPECT_EQ(parse_bag_compression("lz4"), BagCompression::kLz4);
  for (const BagCompression c : {BagCompression::kNone, BagCompression::kBz2, BagCompression::kLz4}) {
    EXPECT_EQ(parse_bag_compression(to_string(c)), c);
  }
  EXPECT_THROW(parse_bag_compression("LZ4"), std::invalid_argument);
  EXPECT_EQ(parse_bag_compression("zstd"), BagCompression::kZstd);  // rosbag2 (MCAP) only
  EXPECT_THROW(parse_bag_compression("zip"), std::invalid_argument);
  const test::TempDir dir("bag_zstd");
  EXPECT_THROW(BagWriter((dir.path() / "x.bag").string(), BagCompression::kZstd), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "x.bag.active"));
}

}  // namespace
}  // namespace stvl::recording

// Bags written here (BagWriter, as `stvl-bench run` exports them, and rosbag's own writer for the layouts
// and encodings BagWriter does not produce) read back through open_recording; every bad-input error.
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Float32.h>
#include <tf2_msgs/TFMessage.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

#include "recording/recording.hpp"
#include "tests/support/command.hpp"
#include "recording/bag_writer.hpp"

namespace stvl::recording {
namespace {

namespace fs = std::filesystem;
constexpr int kWidth = 8, kHeight = 6;

Eigen::Isometry3d pose(double x, double y, double z, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, z);
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

Eigen::Isometry3d optical_on_link() {  // z forward, x right, y down
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return T;
}

sensors::CameraIntrinsics intrinsics() {
  sensors::CameraIntrinsics k;
  k.width = kWidth, k.height = kHeight, k.fx = 6.5, k.fy = 6.0, k.cx = 3.5, k.cy = 2.5;
  return k;
}

std::vector<std::uint16_t> pattern_mm(int frame) {
  std::vector<std::uint16_t> d(kWidth * kHeight);
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = (i + frame) % 5 == 0 ? 0 : std::uint16_t(300 + 13 * i + 100 * frame);
  return d;
}

std::string error_of(const std::string& path, const RecordingOptions& options = {}) {
  try {
    auto recording = open_recording(path, options);
    RecordedFrame frame;
    while (recording->next(frame)) {
    }
  } catch (const std::invalid_argument& e) {
    if (std::getenv("STVL_PRINT_ERRORS")) std::fprintf(stderr, "ERROR: %s\n", e.what());
    return e.what();
  }
  return "(no error)";
}

#define EXPECT_ERROR(path, options, ...)                                                 \
  do {                                                                                   \
    const std::string message = error_of(path, options);                                 \
    for (const char* part : {__VA_ARGS__}) EXPECT_NE(message.find(part), std::string::npos) << message; \
  } while (0)

// rosbag's own writer, for what BagWriter does not write.
class RawBag {
 public:
  explicit RawBag(const fs::path& path, bool lz4_chunk_per_message = false) {
    bag_.open(path.string(), rosbag::bagmode::Write);
    if (lz4_chunk_per_message) bag_.setCompression(rosbag::compression::LZ4), bag_.setChunkThreshold(1);
  }
  void image(const std::string& topic, double t, const std::string& frame, std::uint32_t w, std::uint32_t h,
             const std::string& encoding, bool big_endian, std::uint32_t step, std::vector<std::uint8_t> data) {
    sensor_msgs::Image msg;
    msg.header.stamp = ros::Time(t), msg.header.frame_id = frame;
    msg.width = w, msg.height = h, msg.encoding = encoding, msg.is_bigendian = big_endian, msg.step = step;
    msg.data = std::move(data);
    bag_.write(topic, ros::Time(t), msg);
  }
  // 16UC1 little-endian, packed.
  void image16(const std::string& topic, double t, const std::string& frame, const std::vector<std::uint16_t>& mm) {
    std::vector<std::uint8_t> data(mm.size() * 2);
    for (std::size_t i = 0; i < mm.size(); ++i) data[2 * i] = mm[i] & 0xff, data[2 * i + 1] = mm[i] >> 8;
    image(topic, t, frame, kWidth, kHeight, "16UC1", false, kWidth * 2, data);
  }
  void info(const std::string& topic, double t, const std::string& frame, std::uint32_t w = kWidth,
            std::uint32_t h = kHeight, double fx = 6.5) {
    sensor_msgs::CameraInfo msg;
    msg.header.stamp = ros::Time(t), msg.header.frame_id = frame;
    msg.width = w, msg.height = h;
    msg.K = {fx, 0, 3.5, 0, 6.0, 2.5, 0, 0, 1};
    bag_.write(topic, ros::Time(t), msg);
  }
  void tf(const std::string& topic, double t, const std::string& parent, const std::string& child,
          const Eigen::Isometry3d& T, double quaternion_scale = 1.0) {
    geometry_msgs::TransformStamped tf;
    tf.header.stamp = ros::Time(t), tf.header.frame_id = parent, tf.child_frame_id = child;
    const Eigen::Quaterniond q(T.linear());
    tf.transform.translation.x = T.translation().x(), tf.transform.translation.y = T.translation().y();
    tf.transform.translation.z = T.translation().z();
    tf.transform.rotation.x = q.x() * quaternion_scale, tf.transform.rotation.y = q.y() * quaternion_scale;
    tf.transform.rotation.z = q.z() * quaternion_scale, tf.transform.rotation.w = q.w() * quaternion_scale;
    tf2_msgs::TFMessage msg;
    msg.transforms.push_back(tf);
    bag_.write(topic, ros::Time(t), msg);
  }
  void odom(const std::string& topic, double t, const Eigen::Isometry3d& T, double quaternion_scale = 1.0) {
    nav_msgs::Odometry msg;
    msg.header.stamp = ros::Time(t), msg.header.frame_id = "odom", msg.child_frame_id = "base_link";
    const Eigen::Quaterniond q(T.linear());
    msg.pose.pose.position.x = T.translation().x(), msg.pose.pose.position.y = T.translation().y();
    msg.pose.pose.position.z = T.translation().z();
    msg.pose.pose.orientation.x = q.x() * quaternion_scale, msg.pose.pose.orientation.y = q.y() * quaternion_scale;
    msg.pose.pose.orientation.z = q.z() * quaternion_scale, msg.pose.pose.orientation.w = q.w() * quaternion_scale;
    bag_.write(topic, ros::Time(t), msg);
  }
  void close() { bag_.close(); }

 private:
  rosbag::Bag bag_;
};

const char* kDepth = "/camera/depth/image_rect_raw";
const char* kInfo = "/camera/depth/camera_info";
const char* kOptical = "camera_depth_optical_frame";

// A valid minimal realsense-ros bag: one 16UC1 frame at t = 1 s, no tf.
void write_minimal(RawBag& bag) {
  bag.info(kInfo, 1.0, kOptical);
  bag.image16(kDepth, 1.0, kOptical, pattern_mm(0));
}

void expect_depth_mm(const sensors::DepthImage& depth, const std::vector<std::uint16_t>& mm) {
  ASSERT_EQ(depth.width, kWidth);
  ASSERT_EQ(depth.height, kHeight);
  for (std::size_t i = 0; i < mm.size(); ++i) ASSERT_NEAR(depth.depth_m[i], mm[i] * 1e-3, 1e-6) << "pixel " << i;
}

void expect_pose(const Eigen::Isometry3d& actual, const Eigen::Isometry3d& expected, double tolerance = 1e-9) {
  EXPECT_LT((actual.matrix() - expected.matrix()).cwiseAbs().maxCoeff(), tolerance) << actual.matrix() << "\nvs\n"
                                                                                      << expected.matrix();
}

// --- Our own export ------------------------------------------------------------------------------------------

const Eigen::Isometry3d kBaseCameraLink = pose(0.2, 0.0, 0.3, 0.1);
Eigen::Isometry3d map_odom(int k) { return pose(0.01 * k, -0.02, 0.0, 0.005 * k); }
Eigen::Isometry3d odom_base(int k) { return pose(0.1 * k, 0.05 * k, 0.0, 0.2 * k); }

void write_export(const fs::path& path, BagCompression compression, int frames = 3) {
  BagWriter writer(path.string(), compression);
  writer.write_tf_static(kBaseCameraLink, optical_on_link());
  for (int k = 0; k < frames; ++k) {
    const double t_s = 0.1 * k;
    writer.write_tf(t_s, map_odom(k), odom_base(k));
    writer.write_odometry(t_s, odom_base(k), 0.5, 0.1);
    writer.write_camera_info(t_s, intrinsics());
    writer.write_depth_image(t_s, intrinsics(), pattern_mm(k));
  }
  writer.close();
}

class ExportTest : public ::testing::TestWithParam<BagCompression> {};

TEST_P(ExportTest, ReadsBackDepthAndTfPoses) {
  const test::TempDir dir("rec_export_" + to_string(GetParam()));
  const fs::path path = dir.path() / "run.bag";
  write_export(path, GetParam());
  const auto recording = open_recording(path.string());
  const RecordingInfo& info = recording->info();
  EXPECT_EQ(info.format, "ros1 bag (realsense-ros)");
  EXPECT_EQ(info.depth_topic, kDepth);
  EXPECT_EQ(info.info_topic, kInfo);
  EXPECT_EQ(info.encoding, "16UC1");
  EXPECT_EQ(info.camera_frame, kOptical);
  EXPECT_EQ(info.pose_source, PoseSource::kTf);
  EXPECT_EQ(info.fixed_frame, "map");  // the root of the camera's tree
  EXPECT_EQ(info.frame_count, 3u);
  EXPECT_NEAR(info.start_time_s, kBagTimeOffset_s, 1e-9);
  EXPECT_NEAR(info.end_time_s, kBagTimeOffset_s + 0.2, 1e-9);
  EXPECT_NEAR(info.intrinsics.rate_hz, 10.0, 1e-6);
  RecordedFrame frame;
  int k = 0;
  while (recording->next(frame)) {
    EXPECT_EQ(frame.index, std::size_t(k));
    EXPECT_NEAR(frame.time_s, 0.1 * k, 1e-9);
    expect_depth_mm(frame.depth, pattern_mm(k));
    EXPECT_DOUBLE_EQ(frame.intrinsics.fx, 6.5);
    EXPECT_DOUBLE_EQ(frame.intrinsics.cy, 2.5);
    const Eigen::Isometry3d T_map_base = map_odom(k) * odom_base(k);
    expect_pose(frame.T_fixed_base, T_map_base);
    expect_pose(frame.T_fixed_camera, T_map_base * kBaseCameraLink * optical_on_link());
    ++k;
  }
  EXPECT_EQ(k, 3);
}

INSTANTIATE_TEST_SUITE_P(AllCompressions, ExportTest,
                         ::testing::Values(BagCompression::kNone, BagCompression::kBz2,
                                           BagCompression::kLz4),
                         [](const auto& info) { return to_string(info.param); });

TEST(BagReader, ExportFixedFrameOdom) {
  const test::TempDir dir("rec_export_odom_frame");
  const fs::path path = dir.path() / "run.bag";
  write_export(path, BagCompression::kNone);
  RecordingOptions options;
  options.fixed_frame = "odom";
  const auto recording = open_recording(path.string(), options);
  RecordedFrame frame;
  ASSERT_TRUE(recording->next(frame));
  ASSERT_TRUE(recording->next(frame));
  expect_pose(frame.T_fixed_base, odom_base(1));
}

TEST(BagReader, ExportOdometryPoses) {
  const test::TempDir dir("rec_export_odom");
  const fs::path path = dir.path() / "run.bag";
  write_export(path, BagCompression::kLz4);
  RecordingOptions options;
  options.odom_topic = "/odom";
  options.T_base_camera = pose(9, 9, 9, 0);  // not used: /tf_static links base_link to the camera
  const auto recording = open_recording(path.string(), options);
  EXPECT_EQ(recording->info().pose_source, PoseSource::kOdometry);
  EXPECT_EQ(recording->info().fixed_frame, "odom");
  RecordedFrame frame;
  int k = 0;
  while (recording->next(frame)) {
    expect_pose(frame.T_fixed_base, odom_base(k));
    expect_pose(frame.T_fixed_camera, odom_base(k) * kBaseCameraLink * optical_on_link());
    ++k;
  }
  EXPECT_EQ(k, 3);
}

TEST(BagReader, MultiCameraExport) {
  const test::TempDir dir("rec_multi");
  const fs::path path = dir.path() / "run.bag";
  const Eigen::Isometry3d T_base_rear = pose(-0.2, 0, 0.3, M_PI);
  {
    BagWriter writer(path.string(), BagCompression::kNone);
    writer.write_tf_static({{"front", kBaseCameraLink, optical_on_link()}, {"rear", T_base_rear, optical_on_link()}});
    writer.write_tf(0.0, map_odom(0), odom_base(1));
    for (const char* camera : {"front", "rear"}) {
      writer.write_camera_info(0.0, intrinsics(), camera);
      writer.write_depth_image(0.0, intrinsics(), pattern_mm(std::string(camera) == "rear"), camera);
    }
    writer.close();
  }
  EXPECT_ERROR(path.string(), {}, "several depth topics", "/front/depth/image_rect_raw", "/rear/depth/image_rect_raw",
               "--depth-topic");
  RecordingOptions options;
  options.depth_topic = "/rear/depth/image_rect_raw";
  const auto recording = open_recording(path.string(), options);
  EXPECT_EQ(recording->info().info_topic, "/rear/depth/camera_info");
  EXPECT_EQ(recording->info().camera_frame, "rear_depth_optical_frame");
  RecordedFrame frame;
  ASSERT_TRUE(recording->next(frame));
  expect_depth_mm(frame.depth, pattern_mm(1));
  expect_pose(frame.T_fixed_camera, map_odom(0) * odom_base(1) * T_base_rear * optical_on_link());
}

// --- Layouts, encodings, poses ---------------------------------------------------------------------------------

TEST(BagReader, AlignedDepthTopic) {
  const test::TempDir dir("rec_aligned");
  const fs::path path = dir.path() / "a.bag";
  {
    RawBag bag(path);
    bag.info("/camera/aligned_depth_to_color/camera_info", 1.0, "camera_color_optical_frame");
    bag.image16("/camera/aligned_depth_to_color/image_raw", 1.0, "camera_color_optical_frame", pattern_mm(2));
    bag.image16("/camera/color/image_raw", 1.0, "camera_color_optical_frame", pattern_mm(0));  // not a candidate
    bag.close();
  }
  const auto recording = open_recording(path.string());
  EXPECT_EQ(recording->info().depth_topic, "/camera/aligned_depth_to_color/image_raw");
  EXPECT_EQ(recording->info().info_topic, "/camera/aligned_depth_to_color/camera_info");
  EXPECT_EQ(recording->info().pose_source, PoseSource::kStatic);
  RecordedFrame frame;
  ASSERT_TRUE(recording->next(frame));
  expect_depth_mm(frame.depth, pattern_mm(2));
  EXPECT_FALSE(recording->next(frame));
}

TEST(BagReader, Float32Depth) {
  const test::TempDir dir("rec_32f");
  const fs::path path = dir.path() / "f.bag";
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  std::vector<float> values(kWidth * kHeight, 2.25f);
  values[0] = nan, values[1] = inf, values[2] = -1.5f, values[3] = 0.0f, values[4] = 0.75f, values[5] = -inf;
  {
    RawBag bag(path);
    bag.info(kInfo, 1.0, kOptical);
    std::vector<std::uint8_t> data(values.size() * 4);
    std::memcpy(data.data(), values.data(), data.size());
    bag.image(kDepth, 1.0, kOptical, kWidth, kHeight, "32FC1", false, kWidth * 4, data);
    bag.close();
  }
  const auto recording = open_recording(path.string());
  EXPECT_EQ(recording->info().encoding, "32FC1");
  RecordedFrame frame;
  ASSERT_TRUE(recording->next(frame));
  EXPECT_EQ(frame.depth.depth_m[0], 0.0f);  // NaN
  EXPECT_EQ(frame.depth.depth_m[1], 0.0f);  // Inf
  EXPECT_EQ(frame.depth.depth_m[2], 0.0f);  // negative
  EXPECT_EQ(frame.depth.depth_m[3], 0.0f);
  EXPECT_EQ(frame.depth.depth_m[4], 0.75f);
  EXPECT_EQ(frame.depth.depth_m[5], 0.0f);  // -Inf
  EXPECT_EQ(frame.depth.depth_m[6], 2.25f);
  EXPECT_EQ(frame.depth.valid_count(), kWidth * kHeight - 5);
}

TEST(BagReader, BigEndianAndPaddedRows) {
  const test::TempDir dir("rec_be");
  const fs::path path = dir.path() / "be.bag";
  const auto mm = pattern_mm(1);
  const std::uint32_t step = kWidth * 2 + 6;  // 6 bytes of padding per row
  {
    RawBag bag(path);
    bag.info(kInfo, 1.0, kOptical);
    std::vector<std::uint8_t> big(mm.size() * 2), padded(step * kHeight, 0xAB);
    for (std::size_t i = 0; i < mm.size(); ++i) big[2 * i] = mm[i] >> 8, big[2 * i + 1] = mm[i] & 0xff;
    for (int v = 0; v < kHeight; ++v) {
      for (int u = 0; u < kWidth; ++u) {
        const std::uint16_t d = mm[v * kWidth + u];
        padded[v * step + 2 * u] = d & 0xff, padded[v * step + 2 * u + 1] = d >> 8;
      }
    }
    bag.image(kDepth, 1.0, kOptical, kWidth, kHeight, "mono16", true, kWidth * 2, big);
    bag.image(kDepth, 1.1, kOptical, kWidth, kHeight, "16UC1", false, step, padded);
    bag.close();
  }
  const auto recording = open_recording(path.string());
  RecordedFrame frame;
  ASSERT_TRUE(recording->next(frame));
  expect_depth_mm(frame.depth, mm);  // big-endian
  ASSERT_TRUE(recording->next(frame));
  expect_depth_mm(frame.depth, mm);  // padded rows
  EXPECT_NEAR(frame.time_s, 0.1, 1e-9);
}

TEST(BagReader, TfInterpolatedBetweenStamps) {
  const test::TempDir dir("rec_interp");
  const fs::path path = dir.path() / "i.bag";
  const Eigen::Isometry3d T_base_camera = pose(0.1, 0, 0.5, 0) * optical_on_link();
  {
    RawBag bag(path);
    bag.tf("/tf_static", 1.0, "base_link", kOptical, T_base_camera);
    bag.tf("/tf", 1.0, "odom", "base_link", pose(0, 0, 0, 0));
    bag.tf("/tf", 2.0, "odom", "base_link", pose(1, 2, 0, M_PI / 2));
    bag.info(kInfo, 1.0, kOptical);
    bag.image16(kDepth, 1.25, kOptical, pattern_mm(0));
    bag.image16(kDepth, 2.0, kOptical, pattern_mm(0));
    bag.close();
  }
  const auto recording = open_recording(path.string());
  EXPECT_EQ(recording->info().fixed_frame, "odom");
  RecordedFrame frame;
  ASSERT_TRUE(recording->next(frame));
  // A quarter of the way: translation (0.25, 0.5), yaw 22.5 deg (slerp of a rotation about z).
  expect_pose(frame.T_fixed_base, pose(0.25, 0.5, 0, M_PI / 8), 1e-12);
  expect_pose(frame.T_fixed_camera, pose(0.25, 0.5, 0, M_PI / 8) * T_base_camera, 1e-12);
  ASSERT_TRUE(recording->next(frame));
  expect_pose(frame.T_fixed_base, pose(1, 2, 0, M_PI / 2), 1e-12);
}

TEST(BagReader, OdometryWithoutTfUsesOptionsMount) {
  const test::TempDir dir("rec_odom");
  const fs::path path = dir.path() / "o.bag";
  {
    RawBag bag(path);
    bag.odom("/wheel/odom", 1.0, pose(0, 0, 0, 0));
    bag.odom("/wheel/odom", 3.0, pose(2, 0, 0, -M_PI / 2));
    write_minimal(bag);  // frame at t = 1
    bag.image16(kDepth, 2.0, kOptical, pattern_mm(1));
    bag.close();
  }
  RecordingOptions options;
  options.odom_topic = "/wheel/odom";
  options.T_base_camera = pose(0.3, 0, 0.4, 0) * optical_on_link();
  const auto recording = open_recording(path.string(), options);
  EXPECT_EQ(recording->info().pose_source, PoseSource::kOdometry);
  RecordedFrame frame;
  ASSERT_TRUE(recording->next(frame));
  expect_pose(frame.T_fixed_camera, options.T_base_camera);
  ASSERT_TRUE(recording->next(frame));
  expect_pose(frame.T_fixed_base, pose(1, 0, 0, -M_PI / 4), 1e-12);
  expect_pose(frame.T_fixed_camera, pose(1, 0, 0, -M_PI / 4) * options.T_base_camera, 1e-12);
}

TEST(BagReader, CameraMissingFromTfRidesOnBaseLink) {
  const test::TempDir dir("rec_tf_base");
  const fs::path path = dir.path() / "b.bag";
  {
    RawBag bag(path);
    bag.tf("/tf", 1.0, "odom", "base_link", pose(1, 0, 0, 0.5));  // no /tf_static: the camera is not linked
    write_minimal(bag);
    bag.close();
  }
  RecordingOptions options;
  options.T_base_camera = pose(0.2, 0, 0.3, 0) * optical_on_link();
  const auto recording = open_recording(path.string(), options);
  EXPECT_EQ(recording->info().pose_source, PoseSource::kTf);
  EXPECT_EQ(recording->info().fixed_frame, "odom");
  RecordedFrame frame;
  ASSERT_TRUE(recording->next(frame));
  expect_pose(frame.T_fixed_base, pose(1, 0, 0, 0.5));
  expect_pose(frame.T_fixed_camera, pose(1, 0, 0, 0.5) * options.T_base_camera);
}

TEST(BagReaderErrors, TfFrameWithTwoParentsAndOdometryInAnotherFrame) {
  const test::TempDir dir("rec_err_tree");
  const fs::path path = dir.path() / "t.bag";
  {
    RawBag bag(path);
    bag.tf("/tf", 1.0, "odom", "base_link", pose(0, 0, 0, 0));
    bag.tf("/tf", 1.0, "map", "base_link", pose(0, 0, 0, 0));
    write_minimal(bag);
    bag.close();
  }
  EXPECT_ERROR(path.string(), {}, "t.bag", "frame 'base_link' has two parents ('odom' and 'map')");
  {
    RawBag bag(path);
    bag.odom("/odom", 1.0, pose(0, 0, 0, 0));
    write_minimal(bag);
    bag.close();
  }
  RecordingOptions options;
  options.odom_topic = "/odom";
  options.fixed_frame = "map";
  EXPECT_ERROR(path.string(), options, "t.bag", "fixed frame 'map' but /odom gives poses in 'odom'");
}

TEST(BagReader, NoPoseSourceIsStatic) {
  const test::TempDir dir("rec_static");
  const fs::path path = dir.path() / "s.bag";
  {
    RawBag bag(path);
    write_minimal(bag);
    bag.close();
  }
  RecordingOptions options;
  options.T_fixed_base = pose(1, 2, 0, 0.5);
  options.T_base_camera = pose(0, 0, 0.4, 0) * optical_on_link();
  const auto recording = open_recording(path.string(), options);
  EXPECT_EQ(recording->info().pose_source, PoseSource::kStatic);
  EXPECT_EQ(recording->info().fixed_frame, "world");
  RecordedFrame frame;
  ASSERT_TRUE(recording->next(frame));
  expect_pose(frame.T_fixed_camera, options.T_fixed_base * options.T_base_camera);
  expect_pose(frame.T_fixed_base, options.T_fixed_base);
}

// --- Errors ------------------------------------------------------------------------------------------------

TEST(BagReaderErrors, NotABag) {
  const test::TempDir dir("rec_err_notbag");
  std::ofstream(dir.path() / "x.bag") << "hello\n";
  EXPECT_ERROR((dir.path() / "x.bag").string(), {}, "x.bag", "not a ROS 1 bag");
  EXPECT_ERROR((dir.path() / "missing.bag").string(), {}, "missing.bag", "no such file");
}

TEST(BagReaderErrors, TruncatedRealBag) {
  const fs::path real = fs::path(STVL_REALDATA_DIR) / "d435_office_corner/single_depth_color_640x480.bag";
  if (!fs::exists(real)) GTEST_SKIP() << real << " is absent";
  const test::TempDir dir("rec_err_trunc");
  const std::string bytes = test::TempDir::read(real);
  for (const double fraction : {0.5, 0.99}) {
    const fs::path cut = dir.path() / ("cut" + std::to_string(int(fraction * 100)) + ".bag");
    std::ofstream(cut, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size() * fraction));
    const std::string name = cut.filename().string();  // outlives the check (a temporary's c_str() would not)
    EXPECT_ERROR(cut.string(), {}, name.c_str(), "truncated or corrupt");
  }
}

class CorruptChunkTest : public ::testing::TestWithParam<std::tuple<BagCompression, double>> {};

std::uint32_t read_u32(std::fstream& file, std::streamoff at) {
  unsigned char b[4] = {};
  file.seekg(at);
  file.read(reinterpret_cast<char*>(b), 4);
  return b[0] | b[1] << 8 | b[2] << 16 | std::uint32_t(b[3]) << 24;
}

TEST_P(CorruptChunkTest, InABagThatOpens) {
  const auto [compression, fraction] = GetParam();
  const test::TempDir dir("rec_err_chunk_" + to_string(compression) + std::to_string(int(fraction * 10)));
  const fs::path path = dir.path() / "c.bag";
  write_export(path, compression, 20);
  // Zero bytes at `fraction` of the first chunk's data (the chunk record follows "#ROSBAG V2.0\n" and the
  // 4096-byte bag header record); the index at the end of the file is intact, so the bag opens. Compressed
  // chunks then fail to decompress; an uncompressed chunk has no checksum, so 2 KB are zeroed there to hit record
  // headers (zeroed payloads read as zeros, and the chunk's first ~15 KB are connection records that readers
  // take from the index instead).
  std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
  const std::uint32_t bag_header = read_u32(file, 13);
  const std::streamoff chunk = 13 + 4 + bag_header + 4 + read_u32(file, 13 + 4 + bag_header);
  const std::uint32_t header = read_u32(file, chunk);
  const std::uint32_t data = read_u32(file, chunk + 4 + header);
  ASSERT_GT(data, 2048u);
  file.seekp(chunk + 8 + header + std::streamoff(data * fraction) - (compression == BagCompression::kNone ? 1024 : 32));
  const std::string zeros(compression == BagCompression::kNone ? 2048 : 64, '\0');
  file.write(zeros.data(), std::streamsize(zeros.size()));
  file.close();
  EXPECT_ERROR(path.string(), {}, "c.bag", "corrupt bag");
}

INSTANTIATE_TEST_SUITE_P(Offsets, CorruptChunkTest,
                         ::testing::Combine(::testing::Values(BagCompression::kNone, BagCompression::kBz2,
                                                              BagCompression::kLz4),
                                            ::testing::Values(0.5, 0.8)));

TEST(BagReaderErrors, CorruptChunkFoundWhileReading) {
  const test::TempDir dir("rec_err_chunk_next");
  const fs::path path = dir.path() / "n.bag";
  constexpr std::uint32_t kW = 64, kH = 48;
  constexpr int kFrames = 9;
  {
    RawBag bag(path, /*lz4_chunk_per_message=*/true);
    bag.info(kInfo, 1.0, kOptical, kW, kH);
    std::uint64_t state = 12345;
    for (int k = 0; k < kFrames; ++k) {
      std::vector<std::uint8_t> data(kW * kH * 2);
      for (auto& b : data) state = state * 6364136223846793005ull + 1442695040888963407ull, b = state >> 56;
      bag.image(kDepth, 1.0 + 0.1 * k, kOptical, kW, kH, "16UC1", false, kW * 2, data);  // incompressible
    }
    bag.close();
  }
  // Zero 64 bytes in the middle of the file: inside the 5th image's chunk (one chunk per message, ~6 KB each).
  std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
  file.seekp(std::streamoff(fs::file_size(path) / 2));
  file.write(std::string(64, '\0').data(), 64);
  file.close();
  const auto recording = open_recording(path.string());  // opens: the index and the first and last frames are fine
  RecordedFrame frame;
  std::size_t read = 0;
  try {
    while (recording->next(frame)) ++read;
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("n.bag: /camera/depth/image_rect_raw: frame " + std::to_string(read) + " cannot be read"),
              std::string::npos)
        << message;
  }
  EXPECT_GT(read, 2u);
  EXPECT_LT(read, std::size_t(kFrames) - 2);
}

TEST(BagReaderErrors, NoDepthTopic) {
  const test::TempDir dir("rec_err_nodepth");
  const fs::path path = dir.path() / "n.bag";
  {
    RawBag bag(path);
    bag.tf("/tf", 1.0, "odom", "base_link", pose(0, 0, 0, 0));
    bag.close();
  }
  EXPECT_ERROR(path.string(), {}, "n.bag", "no depth topic", "/tf", "--depth-topic");
}

TEST(BagReaderErrors, NamedTopicsThatDoNotExist) {
  const test::TempDir dir("rec_err_named");
  const fs::path path = dir.path() / "m.bag";
  {
    RawBag bag(path);
    write_minimal(bag);
    bag.close();
  }
  RecordingOptions options;
  options.depth_topic = "/camera/depth/image_rect";
  EXPECT_ERROR(path.string(), options, "m.bag", "no topic /camera/depth/image_rect",
               "nearest existing topic: /camera/depth/image_rect_raw");
  options = {};
  options.info_topic = "/camera/depth/camera_infos";
  EXPECT_ERROR(path.string(), options, "nearest existing topic: /camera/depth/camera_info");
  options = {};
  options.odom_topic = "/odometry";
  EXPECT_ERROR(path.string(), options, "no topic /odometry", "the bag has no nav_msgs/Odometry");
  options = {};
  options.depth_topic = kInfo;
  EXPECT_ERROR(path.string(), options, "is sensor_msgs/CameraInfo, expected sensor_msgs/Image");
}

TEST(BagReaderErrors, MissingCameraInfo) {
  const test::TempDir dir("rec_err_noinfo");
  const fs::path path = dir.path() / "i.bag";
  {
    RawBag bag(path);
    bag.image16(kDepth, 1.0, kOptical, pattern_mm(0));
    bag.close();
  }
  EXPECT_ERROR(path.string(), {}, "no camera info", kInfo, "--info-topic");
}

TEST(BagReaderErrors, EncodingsThatAreNotDepth) {
  for (const char* encoding : {"rgb8", "8UC1", "bgra8"}) {
    const test::TempDir dir(std::string("rec_err_enc_") + encoding);
    const fs::path path = dir.path() / "e.bag";
    {
      RawBag bag(path);
      bag.info(kInfo, 1.0, kOptical);
      bag.image(kDepth, 1.0, kOptical, kWidth, kHeight, encoding, false, kWidth * 3,
                std::vector<std::uint8_t>(kWidth * kHeight * 3));
      bag.close();
    }
    const std::string named = std::string("encoding '") + encoding + "'";
    EXPECT_ERROR(path.string(), {}, "e.bag", kDepth, named.c_str(), "is not depth");
  }
}

TEST(BagReaderErrors, ImageDisagreesWithItself) {
  struct Case {
    const char* name;
    std::uint32_t width, step;
    std::size_t bytes;
    const char* message;
  };
  const Case cases[] = {
      {"size", kWidth + 1, (kWidth + 1) * 2, (kWidth + 1) * 2 * kHeight, "camera_info says 8x6"},
      {"step", kWidth, kWidth * 2 - 1, kWidth * 2 * kHeight, "step 15 < width x 2 bytes = 16"},
      {"data", kWidth, kWidth * 2, kWidth * 2 * kHeight - 1, "data has 95 bytes < step x height = 96"},
      {"zero", 0, 0, 0, "empty image"},
  };
  for (const Case& c : cases) {
    const test::TempDir dir(std::string("rec_err_img_") + c.name);
    const fs::path path = dir.path() / "d.bag";
    {
      RawBag bag(path);
      bag.info(kInfo, 1.0, kOptical);
      bag.image16(kDepth, 1.0, kOptical, pattern_mm(0));  // a good first frame
      bag.image(kDepth, 1.1, kOptical, c.width, c.width ? kHeight : 0, "16UC1", false, c.step,
                std::vector<std::uint8_t>(c.bytes));
      bag.close();
    }
    EXPECT_ERROR(path.string(), {}, "d.bag", kDepth, "frame 1", c.message);
  }
}

TEST(BagReaderErrors, BadIntrinsics) {
  struct Case {
    const char* name;
    std::uint32_t width, height;
    double fx;
    const char* message;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const Case& c : {Case{"fx0", kWidth, kHeight, 0.0, "fx = 0"}, Case{"fxnan", kWidth, kHeight, nan, "fx = nan"},
                        Case{"w0", 0, kHeight, 6.5, "width = 0"}, Case{"h0", kWidth, 0, 6.5, "height = 0"}}) {
    const test::TempDir dir(std::string("rec_err_k_") + c.name);
    const fs::path path = dir.path() / "k.bag";
    {
      RawBag bag(path);
      bag.info(kInfo, 1.0, kOptical, c.width, c.height, c.fx);
      bag.image16(kDepth, 1.0, kOptical, pattern_mm(0));
      bag.close();
    }
    EXPECT_ERROR(path.string(), {}, "k.bag", kInfo, "bad intrinsics", c.message);
  }
}

TEST(BagReaderErrors, NonRigidTransforms) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const double scale : {2.0, 0.9, nan}) {
    const test::TempDir dir("rec_err_rigid_" + std::to_string(scale));
    const fs::path tf_bag = dir.path() / "tf.bag", odom_bag = dir.path() / "odom.bag";
    {
      RawBag bag(tf_bag);
      bag.tf("/tf", 1.0, "odom", kOptical, pose(0, 0, 0, 0.3), scale);
      write_minimal(bag);
      bag.close();
      RawBag odom(odom_bag);
      odom.odom("/odom", 1.0, pose(0, 0, 0, 0.3), scale);
      write_minimal(odom);
      odom.close();
    }
    const char* what = std::isnan(scale) ? "not finite" : "not a rigid transform";
    EXPECT_ERROR(tf_bag.string(), {}, "tf.bag", "/tf odom -> camera_depth_optical_frame", what);
    RecordingOptions options;
    options.odom_topic = "/odom";
    EXPECT_ERROR(odom_bag.string(), options, "odom.bag", "/odom pose", what);
  }
}

TEST(BagReaderErrors, NoPoseAtAFramesTime) {
  const test::TempDir dir("rec_err_nopose");
  const fs::path path = dir.path() / "p.bag";
  {
    RawBag bag(path);
    bag.tf("/tf", 1.5, "odom", kOptical, pose(0, 0, 0, 0));
    bag.tf("/tf", 2.0, "odom", kOptical, pose(1, 0, 0, 0));
    write_minimal(bag);  // frame at t = 1, before the first tf
    bag.close();
  }
  EXPECT_ERROR(path.string(), {}, "p.bag", "no pose at t = 1.0", "odom -> camera_depth_optical_frame",
               "[1.500000, 2.000000]");
  RecordingOptions options;
  options.odom_topic = "/odom";
  {
    RawBag bag(path);
    bag.odom("/odom", 0.5, pose(0, 0, 0, 0));
    bag.odom("/odom", 1.0, pose(1, 0, 0, 0));
    write_minimal(bag);  // frame 0 at t = 1: read
    bag.image16(kDepth, 1.5, kOptical, pattern_mm(0));  // after the last odometry
    bag.close();
  }
  EXPECT_ERROR(path.string(), options, "p.bag", "frame_id", "frame 1", "no pose at t = 1.5", "/odom covers only");
}

TEST(BagReaderErrors, UnknownFixedFrame) {
  const test::TempDir dir("rec_err_fixed");
  const fs::path path = dir.path() / "f.bag";
  write_export(path, BagCompression::kNone);
  RecordingOptions options;
  options.fixed_frame = "world";
  EXPECT_ERROR(path.string(), options, "fixed frame 'world' is not above 'camera_depth_optical_frame'");
}

}  // namespace
}  // namespace stvl::recording

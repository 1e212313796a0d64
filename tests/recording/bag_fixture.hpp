#pragma once
// Bags written by the bag reader's tests: our own export (BagWriter) and rosbag's writer for the other layouts,
// with helpers to compare what the reader gives back.
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

#include "recording/bag_writer.hpp"
#include "recording/recording.hpp"
#include "tests/support/command.hpp"

namespace stvl::recording {
namespace bag_test {

namespace fs = std::filesystem;
constexpr int kWidth = 8, kHeight = 6;

inline Eigen::Isometry3d pose(double x, double y, double z, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, z);
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

inline Eigen::Isometry3d optical_on_link() {  // z forward, x right, y down
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return T;
}

inline sensors::CameraIntrinsics intrinsics() {
  sensors::CameraIntrinsics k;
  k.width = kWidth, k.height = kHeight, k.fx = 6.5, k.fy = 6.0, k.cx = 3.5, k.cy = 2.5;
  return k;
}

inline std::vector<std::uint16_t> pattern_mm(int frame) {
  std::vector<std::uint16_t> d(kWidth * kHeight);
  for (std::size_t i = 0; i < d.size(); ++i)
    d[i] = (i + frame) % 5 == 0 ? 0 : std::uint16_t(300 + 13 * i + 100 * frame);
  return d;
}

inline std::string error_of(const std::string& path, const RecordingOptions& options = {}) {
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

#define EXPECT_ERROR(path, options, ...)                                                                \
  do {                                                                                                  \
    const std::string message = error_of(path, options);                                                \
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

inline const char* kDepth = "/camera/depth/image_rect_raw";
inline const char* kInfo = "/camera/depth/camera_info";
inline const char* kOptical = "camera_depth_optical_frame";

// A valid minimal realsense-ros bag: one 16UC1 frame at t = 1 s, no tf.
inline void write_minimal(RawBag& bag) {
  bag.info(kInfo, 1.0, kOptical);
  bag.image16(kDepth, 1.0, kOptical, pattern_mm(0));
}

inline void expect_depth_mm(const sensors::DepthImage& depth, const std::vector<std::uint16_t>& mm) {
  ASSERT_EQ(depth.width, kWidth);
  ASSERT_EQ(depth.height, kHeight);
  for (std::size_t i = 0; i < mm.size(); ++i) ASSERT_NEAR(depth.depth_m[i], mm[i] * 1e-3, 1e-6) << "pixel " << i;
}

inline void expect_pose(const Eigen::Isometry3d& actual, const Eigen::Isometry3d& expected, double tolerance = 1e-9) {
  EXPECT_LT((actual.matrix() - expected.matrix()).cwiseAbs().maxCoeff(), tolerance) << actual.matrix() << "\nvs\n"
                                                                                    << expected.matrix();
}

// --- Our own export ------------------------------------------------------------------------------------------

inline const Eigen::Isometry3d kBaseCameraLink = pose(0.2, 0.0, 0.3, 0.1);
inline Eigen::Isometry3d map_odom(int k) { return pose(0.01 * k, -0.02, 0.0, 0.005 * k); }
inline Eigen::Isometry3d odom_base(int k) { return pose(0.1 * k, 0.05 * k, 0.0, 0.2 * k); }

inline void write_export(const fs::path& path, BagCompression compression, int frames = 3) {
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

// Every frame of a recording, as open_recording reads it.
inline std::vector<RecordedFrame> frames_of(const fs::path& path) {
  std::vector<RecordedFrame> frames;
  auto recording = open_recording(path.string());
  RecordedFrame frame;
  while (recording->next(frame)) frames.push_back(frame);
  return frames;
}

// The frames are the same: depth, intrinsics, stamps and poses, exactly.
inline void expect_same_frames(const std::vector<RecordedFrame>& actual, const std::vector<RecordedFrame>& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t i = 0; i < actual.size(); ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    const auto &a = actual[i], &e = expected[i];
    EXPECT_EQ(a.depth.width, e.depth.width);
    EXPECT_EQ(a.depth.height, e.depth.height);
    EXPECT_EQ(a.depth.depth_m, e.depth.depth_m);
    EXPECT_EQ(a.intrinsics.width, e.intrinsics.width);
    EXPECT_EQ(a.intrinsics.height, e.intrinsics.height);
    EXPECT_EQ(a.intrinsics.fx, e.intrinsics.fx);
    EXPECT_EQ(a.intrinsics.fy, e.intrinsics.fy);
    EXPECT_EQ(a.intrinsics.cx, e.intrinsics.cx);
    EXPECT_EQ(a.intrinsics.cy, e.intrinsics.cy);
    EXPECT_EQ(a.stamp_s, e.stamp_s);
    EXPECT_EQ(a.time_s, e.time_s);
    EXPECT_EQ(a.T_fixed_camera.matrix(), e.T_fixed_camera.matrix());
  }
}

}  // namespace bag_test
}  // namespace stvl::recording

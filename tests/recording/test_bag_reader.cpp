// Bags written here (BagWriter, as `stvl-bench run` exports them, and rosbag's own writer for the layouts
// and encodings BagWriter does not produce) read back through open_recording; every bad-input error.
#include "recording/recording.hpp"

#include <gtest/gtest.h>

#include "tests/recording/bag_fixture.hpp"

namespace stvl::recording {
namespace {

using namespace bag_test;
namespace fs = std::filesystem;

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
                         ::testing::Values(BagCompression::kNone, BagCompression::kBz2, BagCompression::kLz4),
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

}  // namespace
}  // namespace stvl::recording

// The real recordings in ../shared/realdata (see its README.md): a librealsense D435 bag and Kinect PNG frames.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "recording/recording.hpp"
#include "tests/support/command.hpp"

namespace stvl::recording {
namespace {

namespace fs = std::filesystem;

const fs::path kRealData = STVL_REALDATA_DIR;
const fs::path kD435Bag = kRealData / "d435_office_corner/single_depth_color_640x480.bag";
const fs::path kKinect = kRealData / "robot_kinect_frames";

struct PythonFrame {
  double stamp_s = 0;
  int width = 0, height = 0, valid = 0;
  double min_m = 0, max_m = 0;
};

// The same bag decoded by python3-rosbag (depth_stats.py), not by our reader.
std::vector<PythonFrame> python_frames(const fs::path& bag, const std::string& topic, double unit_m) {
  const auto outcome =
      test::run_shell("/usr/bin/python3 " + std::string(STVL_SOURCE_DIR) + "/tests/recording/depth_stats.py " +
                      test::quoted(bag.string()) + " " + test::quoted(topic) + " " + std::to_string(unit_m));
  EXPECT_EQ(outcome.exit_code, 0) << outcome.output;
  std::vector<PythonFrame> frames;
  std::istringstream lines(outcome.output);
  std::string word;
  while (lines >> word) {
    if (word != "frame") continue;
    PythonFrame f;
    lines >> f.stamp_s >> f.width >> f.height >> f.valid >> f.min_m >> f.max_m;
    frames.push_back(f);
  }
  return frames;
}

TEST(RealData, D435BagFromLibrealsense) {
  if (!fs::exists(kD435Bag)) GTEST_SKIP() << kD435Bag << " is absent";
  const auto recording = open_recording(kD435Bag.string());
  const RecordingInfo& info = recording->info();
  EXPECT_EQ(info.format, "ros1 bag (librealsense)");
  EXPECT_EQ(info.depth_topic, "/device_0/sensor_0/Depth_0/image/data");
  EXPECT_EQ(info.info_topic, "/device_0/sensor_0/Depth_0/info/camera_info");
  EXPECT_EQ(info.encoding, "mono16");
  EXPECT_EQ(info.pose_source, PoseSource::kStatic);  // no tf in a librealsense recording
  EXPECT_NEAR(info.depth_unit_m, 0.001, 1e-9);       // the "Depth Units" option (a float32 0.001)
  // The realdata README's figures: fx = fy = 390.43, cx 331.39, cy 242.19 (rounded to 0.01 px).
  EXPECT_EQ(info.intrinsics.width, 640);
  EXPECT_EQ(info.intrinsics.height, 480);
  EXPECT_NEAR(info.intrinsics.fx, 390.43, 0.005);
  EXPECT_NEAR(info.intrinsics.fy, 390.43, 0.005);
  EXPECT_NEAR(info.intrinsics.cx, 331.39, 0.005);
  EXPECT_NEAR(info.intrinsics.cy, 242.19, 0.005);
  ASSERT_EQ(info.frame_count, 2u);
  // Every topic is listed; three are read (the realdata README: 2 depth frames, 1 camera_info, device options).
  std::map<std::string, std::string> read;
  for (const auto& t : info.topics)
    if (!t.use.empty()) read[t.use] = t.name + " " + std::to_string(t.messages);
  EXPECT_GT(info.topics.size(), 10u);
  EXPECT_EQ(read,
            (std::map<std::string, std::string>{{"depth", "/device_0/sensor_0/Depth_0/image/data 2"},
                                                {"camera_info", "/device_0/sensor_0/Depth_0/info/camera_info 1"},
                                                {"depth_units", "/device_0/sensor_0/option/Depth Units/value 1"}}));

  const auto expected = python_frames(kD435Bag, info.depth_topic, info.depth_unit_m);
  ASSERT_EQ(expected.size(), 2u);
  RecordedFrame frame;
  std::size_t n = 0;
  while (recording->next(frame)) {
    ASSERT_LT(n, expected.size());
    const PythonFrame& e = expected[n];
    EXPECT_EQ(frame.index, n);
    EXPECT_NEAR(frame.stamp_s, e.stamp_s, 1e-6);
    EXPECT_NEAR(frame.time_s, e.stamp_s - expected[0].stamp_s, 1e-6);
    ASSERT_EQ(frame.depth.width, e.width);
    ASSERT_EQ(frame.depth.height, e.height);
    // Valid pixels: exactly python3-rosbag's count; and the README's "93 % valid", a figure rounded to the
    // percent, so within [92.5, 93.5) %.
    EXPECT_EQ(frame.depth.valid_count(), e.valid);
    const double valid_fraction = double(frame.depth.valid_count()) / (e.width * e.height);
    EXPECT_GE(valid_fraction, 0.925);
    EXPECT_LT(valid_fraction, 0.935);
    float min_m = 1e9f, max_m = 0;
    for (float d : frame.depth.depth_m) {
      if (d > 0) min_m = std::min(min_m, d), max_m = std::max(max_m, d);
    }
    EXPECT_NEAR(min_m, e.min_m, 1e-6);
    EXPECT_NEAR(max_m, e.max_m, 1e-6);
    // The README's "0.34 to 3.2 m" (rounded to 0.01 m and 0.1 m).
    EXPECT_NEAR(min_m, 0.34, 0.005);
    EXPECT_LE(max_m, 3.25);
    EXPECT_GE(max_m, 3.0);  // the second frame's farthest pixel is 3.07 m (python3-rosbag)
    EXPECT_TRUE(frame.T_fixed_camera.isApprox(Eigen::Isometry3d::Identity()));
    ++n;
  }
  EXPECT_EQ(n, 2u);
  EXPECT_FALSE(recording->next(frame));
}

TEST(RealData, KinectFramesWithRtabmapCalibration) {
  if (!fs::exists(kKinect)) GTEST_SKIP() << kKinect << " is absent";
  const auto recording = open_recording(kKinect.string());
  const RecordingInfo& info = recording->info();
  EXPECT_EQ(info.format, "png folder");
  EXPECT_EQ(info.pose_source, PoseSource::kFile);  // the per-frame calibration's local_transform
  ASSERT_EQ(info.frame_count, 2u);
  // calib/17.yaml's local_transform (base_link -> optical frame), as written there.
  Eigen::Matrix<double, 3, 4> local;
  local << -1.46162510e-03, 5.99460006e-02, 9.98200655e-01, 6.20153509e-02,  //
      -9.99999106e-01, -8.77380371e-05, -1.45888329e-03, -1.63501027e-04,    //
      -2.98023224e-08, -9.98201728e-01, 5.99459410e-02, 4.28920656e-01;
  RecordedFrame frame;
  std::vector<std::size_t> order;
  while (recording->next(frame)) {
    EXPECT_EQ(frame.intrinsics.width, 640);
    EXPECT_EQ(frame.intrinsics.height, 480);
    EXPECT_DOUBLE_EQ(frame.intrinsics.fx, 525.0);
    EXPECT_DOUBLE_EQ(frame.intrinsics.fy, 525.0);
    EXPECT_DOUBLE_EQ(frame.intrinsics.cx, 319.5);
    EXPECT_DOUBLE_EQ(frame.intrinsics.cy, 239.5);
    // Static camera: T_fixed_camera = T_fixed_base (identity) * local_transform.
    EXPECT_TRUE(frame.T_fixed_base.isApprox(Eigen::Isometry3d::Identity()));
    if (frame.index == 0) {
      EXPECT_LT((frame.T_fixed_camera.matrix().topRows<3>() - local).cwiseAbs().maxCoeff(), 1e-6);
    }
    EXPECT_NEAR(frame.T_fixed_camera.translation().z(), 0.43, 0.005);  // "about 0.43 m above the base"
    // Optical axis (z) points forward, along base_link's x.
    EXPECT_GT(frame.T_fixed_camera.linear().col(2).x(), 0.99);
    // README: 76 % valid (both frames together), median 3.4 to 3.9 m.
    const double valid_fraction = double(frame.depth.valid_count()) / (640.0 * 480.0);
    EXPECT_GT(valid_fraction, 0.5);
    std::vector<float> valid;
    for (float d : frame.depth.depth_m)
      if (d > 0) valid.push_back(d);
    std::nth_element(valid.begin(), valid.begin() + valid.size() / 2, valid.end());
    EXPECT_GE(valid[valid.size() / 2], 3.35);
    EXPECT_LE(valid[valid.size() / 2], 3.95);
    order.push_back(frame.index);
  }
  EXPECT_EQ(order, (std::vector<std::size_t>{0, 1}));
  EXPECT_NEAR(frame.stamp_s, 1.0 / 30.0, 1e-12);  // no timestamps: frame k at k / rate_hz (30 by default)
}

}  // namespace
}  // namespace stvl::recording

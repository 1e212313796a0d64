// Folders of 16-bit depth PNGs written here: intrinsics.yaml or OpenCV calib/, TUM poses, timestamps; the errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "common/png.hpp"
#include "recording/recording.hpp"
#include "tests/support/command.hpp"

namespace stvl::recording {
namespace {

namespace fs = std::filesystem;
constexpr int kWidth = 6, kHeight = 4;

std::vector<std::uint16_t> pattern(int frame, int width = kWidth, int height = kHeight) {
  std::vector<std::uint16_t> d(std::size_t(width) * height);
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = i % 4 == 0 ? 0 : std::uint16_t(500 + 17 * i + 1000 * frame);
  return d;
}

void write_depth(const fs::path& file, int frame, int width = kWidth, int height = kHeight) {
  const auto d = pattern(frame, width, height);
  write_png(file, width, height, PngFormat::kGray16, d.data());
}

void write_intrinsics(const fs::path& dir, const std::string& extra = "") {
  std::ofstream(dir / "intrinsics.yaml") << "width: 6\nheight: 4\nfx: 5.5\nfy: 5.0\ncx: 2.5\ncy: 1.5\n" << extra;
}

std::string error_of(const fs::path& path) {
  try {
    auto recording = open_recording(path.string());
    RecordedFrame frame;
    while (recording->next(frame)) {
    }
  } catch (const std::invalid_argument& e) {
    if (std::getenv("STVL_PRINT_ERRORS")) std::fprintf(stderr, "ERROR: %s\n", e.what());
    return e.what();
  }
  return "(no error)";
}

#define EXPECT_ERROR(path, ...)                                                                         \
  do {                                                                                                  \
    const std::string message = error_of(path);                                                         \
    for (const char* part : {__VA_ARGS__}) EXPECT_NE(message.find(part), std::string::npos) << message; \
  } while (0)

TEST(PngFolder, NumericOrderScaleRateTimestampsAndPoses) {
  const test::TempDir dir("rec_png");
  fs::create_directories(dir.path() / "depth");
  // Written out of order: 10 sorts after 2 (numerically), not before it (by name).
  write_depth(dir.path() / "depth/10.png", 2);
  write_depth(dir.path() / "depth/1.png", 0);
  write_depth(dir.path() / "depth/2.png", 1);
  write_intrinsics(dir.path(), "depth_scale_m: 0.0005\nrate_hz: 15\n");
  std::ofstream(dir.path() / "poses.txt") << "# timestamp tx ty tz qx qy qz qw\n"
                                          << "100.0 1 2 3 0 0 0 1\n\n"
                                          << "100.5 1.5 2 3 0 0 0.7071067811865476 0.7071067811865476\n"
                                          << "101.0 2 2 3 0 0 1 0\n";
  RecordingOptions options;
  options.T_base_camera.translation() = Eigen::Vector3d(0, 0, 0.5);
  const auto recording = open_recording(dir.path().string(), options);
  const RecordingInfo& info = recording->info();
  EXPECT_EQ(info.format, "png folder");
  EXPECT_EQ(info.encoding, "png16");
  EXPECT_EQ(info.pose_source, PoseSource::kFile);
  EXPECT_EQ(info.frame_count, 3u);
  EXPECT_DOUBLE_EQ(info.intrinsics.fx, 5.5);
  EXPECT_DOUBLE_EQ(info.intrinsics.cy, 1.5);
  EXPECT_DOUBLE_EQ(info.intrinsics.rate_hz, 15.0);
  EXPECT_DOUBLE_EQ(info.start_time_s, 100.0);  // the poses' timestamps
  EXPECT_DOUBLE_EQ(info.end_time_s, 101.0);
  RecordedFrame frame;
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(recording->next(frame));
    EXPECT_DOUBLE_EQ(frame.time_s, 0.5 * k);
    const auto mm = pattern(k);
    for (std::size_t i = 0; i < mm.size(); ++i) ASSERT_FLOAT_EQ(frame.depth.depth_m[i], float(mm[i] * 0.0005));
    EXPECT_NEAR(frame.T_fixed_camera.translation().x(), 1 + 0.5 * k, 1e-12);
    // T_fixed_base = T_fixed_camera * inverse(T_base_camera).
    EXPECT_TRUE((frame.T_fixed_base * options.T_base_camera).isApprox(frame.T_fixed_camera, 1e-12));
  }
  EXPECT_NEAR(Eigen::AngleAxisd(frame.T_fixed_camera.linear()).angle(), M_PI, 1e-9);
  EXPECT_FALSE(recording->next(frame));
}

TEST(PngFolder, TimestampsFileAndRate) {
  const test::TempDir dir("rec_png_times");
  write_depth(dir.path() / "a.png", 0);
  write_depth(dir.path() / "b.png", 1);
  write_intrinsics(dir.path(), "rate_hz: 4\n");
  {
    const auto recording = open_recording(dir.path().string());
    EXPECT_EQ(recording->info().pose_source, PoseSource::kStatic);
    EXPECT_DOUBLE_EQ(recording->info().end_time_s, 0.25);  // frame k at k / rate_hz
  }
  std::ofstream(dir.path() / "timestamps.txt") << "5.0\n5.2\n";
  const auto recording = open_recording(dir.path().string());
  RecordedFrame frame;
  ASSERT_TRUE(recording->next(frame));
  ASSERT_TRUE(recording->next(frame));
  EXPECT_DOUBLE_EQ(frame.stamp_s, 5.2);
  EXPECT_NEAR(frame.time_s, 0.2, 1e-12);
}

TEST(PngFolder, OpenCvCalibrationPerFrame) {
  const test::TempDir dir("rec_png_calib");
  fs::create_directories(dir.path() / "depth");
  fs::create_directories(dir.path() / "calib");
  write_depth(dir.path() / "depth/3.png", 0);
  std::ofstream(dir.path() / "calib/3.yaml")
      << "%YAML:1.0\n---\ncamera_name: \"3\"\nimage_width: 6\nimage_height: 4\n"
      << "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 5., 0., 2.5, 0., 5., 1.5, 0., "
         "0., 1. ]\n"
      << "local_transform:\n   rows: 3\n   cols: 4\n   data: [ 0., 0., 1., 0.1, -1., 0., 0., 0., 0., -1., 0., 0.4 ]\n";
  const auto recording = open_recording(dir.path().string());
  RecordedFrame frame;
  ASSERT_TRUE(recording->next(frame));
  EXPECT_DOUBLE_EQ(frame.intrinsics.fx, 5.0);
  EXPECT_DOUBLE_EQ(frame.T_fixed_camera.translation().z(), 0.4);
  EXPECT_DOUBLE_EQ(frame.T_fixed_camera.linear()(0, 2), 1.0);  // optical z along base x
}

TEST(PngFolderErrors, EveryBadInput) {
  const test::TempDir dir("rec_png_err");
  const fs::path d = dir.path();
  EXPECT_ERROR(d, "empty folder");

  write_depth(d / "1.png", 0);
  EXPECT_ERROR(d, "missing intrinsics", "intrinsics.yaml");
  write_intrinsics(d, "fxx: 3\n");
  EXPECT_ERROR(d, "intrinsics.yaml:7: fxx: unknown key", "did you mean fx");
  std::ofstream(d / "intrinsics.yaml") << "width: 6\nheight: 4\nfx: 0\nfy: 5.0\ncx: 2.5\ncy: 1.5\n";
  EXPECT_ERROR(d, "intrinsics.yaml", "bad intrinsics: fx = 0");
  std::ofstream(d / "intrinsics.yaml") << "width: 6\nheight: 4\nfx: five\nfy: 5.0\ncx: 2.5\ncy: 1.5\n";
  EXPECT_ERROR(d, "intrinsics.yaml:3: fx: expected a number");
  std::ofstream(d / "intrinsics.yaml") << "width: 6\nheight: 4\nfy: 5.0\ncx: 2.5\ncy: 1.5\n";
  EXPECT_ERROR(d, "intrinsics.yaml: fx: required key is missing");
  write_intrinsics(d);
  EXPECT_EQ(error_of(d), "(no error)");

  write_depth(d / "2.png", 1, kWidth + 1, kHeight);
  EXPECT_ERROR(d, "2.png", "mixed files", "7x4 but the intrinsics say 6x4");
  fs::remove(d / "2.png");
  const std::vector<std::uint8_t> rgb(kWidth * kHeight * 3, 7);
  write_png(d / "2.png", kWidth, kHeight, PngFormat::kRgb8, rgb.data());
  EXPECT_ERROR(d, "2.png", "mixed files", "8-bit colour PNG");
  fs::remove(d / "2.png");
  std::ofstream(d / "notes.txt") << "hello\n";
  EXPECT_ERROR(d, "mixed files", "'notes.txt' is not a depth PNG");
  fs::remove(d / "notes.txt");
  std::ofstream(d / "3.png") << "not a png\n";
  EXPECT_ERROR(d, "3.png", "mixed files: not a PNG");
  fs::remove(d / "3.png");

  std::ofstream(d / "poses.txt") << "0 1 2 3 0 0 0\n";
  EXPECT_ERROR(d, "poses.txt:1", "bad pose line");
  std::ofstream(d / "poses.txt") << "# header\n0 1 2 3 0 0 0 1 9\n";
  EXPECT_ERROR(d, "poses.txt:2", "bad pose line");
  std::ofstream(d / "poses.txt") << "0 1 2 3 0 0 0 1.2\n";
  EXPECT_ERROR(d, "poses.txt:1", "not a rigid transform", "quaternion norm 1.2");
  std::ofstream(d / "poses.txt") << "0 1 2 3 0 0 0 1\n1 1 2 3 0 0 0 1\n";
  EXPECT_ERROR(d, "poses.txt", "2 poses for 1 depth PNGs");
  fs::remove(d / "poses.txt");
  std::ofstream(d / "timestamps.txt") << "zero\n";
  EXPECT_ERROR(d, "timestamps.txt:1", "expected a time");
  fs::remove(d / "timestamps.txt");

  fs::create_directories(d / "calib");
  EXPECT_ERROR(d, "both intrinsics.yaml and calib/");
  fs::remove(d / "intrinsics.yaml");
  EXPECT_ERROR(d, "calib/1.yaml", "missing calibration");
  std::ofstream(d / "calib/1.yaml") << "%YAML:1.0\nimage_width: 6\nimage_height: 4\ncamera_matrix:\n  data: [1, 2]\n";
  EXPECT_ERROR(d, "calib/1.yaml", "camera_matrix.data: expected 9 numbers");
  std::ofstream(d / "calib/1.yaml")
      << "%YAML:1.0\nimage_width: 6\nimage_height: 4\ncamera_matrix:\n  data: [5, 0, 2.5, 0, 5, 1.5, 0, 0, 1]\n"
      << "local_transform:\n  data: [2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0]\n";
  EXPECT_ERROR(d, "calib/1.yaml: local_transform", "not a rigid transform");
}

}  // namespace
}  // namespace stvl::recording

// The bag reader on bad input: not a bag, truncated or corrupt chunks, missing or wrong topics, encodings,
// intrinsics, transforms and times: each a std::invalid_argument naming the file and what is wrong.
#include "recording/recording.hpp"

#include <gtest/gtest.h>

#include "tests/recording/bag_fixture.hpp"

namespace stvl::recording {
namespace {

using namespace bag_test;
namespace fs = std::filesystem;

TEST(BagReaderErrors, NotABag) {
  const test::TempDir dir("rec_err_notbag");
  std::ofstream(dir.path() / "x.bag") << "hello\n";
  EXPECT_ERROR((dir.path() / "x.bag").string(), {}, "x.bag", "neither a ROS 1 bag");
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
    write_minimal(bag);                                 // frame 0 at t = 1: read
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

// rosbag2's folder layouts: rosbag2's own recordings (../shared/realdata/rosbag2: metadata versions 4 to 8, split
// MCAP, split .db3 without metadata.yaml) listed with the counts their metadata.yaml gives; files and messages
// compressed with zstd (compression_mode FILE and MESSAGE) read as the same frames; newer metadata versions
// warned about; a split bag's file cut short before its last refused, its last file cut short read with a warning.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "recording/bag_writer.hpp"
#include "recording/mcap.hpp"
#include "recording/recording.hpp"
#include "tests/recording/bag_fixture.hpp"

namespace stvl::recording {
namespace {

using namespace bag_test;
namespace fs = std::filesystem;
const fs::path kRosbag2 = fs::path(STVL_REALDATA_DIR) / "rosbag2";

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// A rosbag2 export of three depth frames with tf and camera info: the folder dir/b with b_0.mcap.
fs::path write_ros2_export(const fs::path& dir) {
  auto writer = make_bag_writer((dir / "b.mcap").string(), BagFormat::kRos2, BagCompression::kZstd);
  writer->write_tf_static({{"camera", kBaseCameraLink, optical_on_link()}});
  for (int k = 0; k < 3; ++k) {
    const double t_s = 0.1 * k;
    writer->write_tf(t_s, map_odom(k), odom_base(k));
    writer->write_camera_info(t_s, intrinsics());
    writer->write_depth_image(t_s, intrinsics(), pattern_mm(k));
  }
  writer->close();
  return dir / "b";
}

// metadata.yaml naming `files`, with a compression mode.
void write_metadata(const fs::path& folder, const std::vector<std::string>& files, const std::string& mode = "",
                    const std::string& format = "", int version = 9) {
  std::ostringstream y;
  y << "rosbag2_bagfile_information:\n  version: " << version << "\n  storage_identifier: mcap\n"
    << "  compression_format: \"" << format << "\"\n  compression_mode: \"" << mode << "\"\n  relative_file_paths:\n";
  for (const auto& f : files) y << "    - " << f << "\n";
  write_bytes(folder / "metadata.yaml", y.str());
}

TEST(Ros2Layouts, Rosbag2sOwnRecordingsListEveryTopicWithTheCountsOfTheirMetadata) {
  if (!fs::exists(kRosbag2)) GTEST_SKIP() << kRosbag2 << " is absent (it lies beside the checkout in CI)";
  int folders = 0;
  for (const auto& entry : fs::directory_iterator(kRosbag2)) {
    SCOPED_TRACE(entry.path().string());
    const RecordingContents contents = list_recording(entry.path().string());
    EXPECT_EQ(contents.format.rfind("rosbag2 (", 0), 0u) << contents.format;
    ASSERT_FALSE(contents.topics.empty());
    ++folders;
    const fs::path yaml = entry.path() / "metadata.yaml";
    if (!fs::exists(yaml)) {  // split_sqlite3: three .db3 files, as left before `ros2 bag reindex`
      ASSERT_EQ(contents.files.size(), 3u);
      for (int i = 0; i < 3; ++i)
        EXPECT_EQ(fs::path(contents.files[i]).filename(), "multiple_files_" + std::to_string(i) + ".db3");
      continue;
    }
    const YAML::Node info = YAML::LoadFile(yaml.string())["rosbag2_bagfile_information"];
    EXPECT_EQ(contents.files.size(), info["relative_file_paths"].size());
    std::map<std::string, std::uint64_t> expected;
    for (const auto& t : info["topics_with_message_count"])
      expected[t["topic_metadata"]["name"].as<std::string>()] = t["message_count"].as<std::uint64_t>();
    std::map<std::string, std::uint64_t> listed;
    for (const auto& t : contents.topics) {
      listed[t.name] = t.messages;
      EXPECT_EQ(t.message_encoding, "cdr") << t.name;
      EXPECT_EQ(t.note, "") << t.name << ": every schema rosbag2 wrote parses";
    }
    EXPECT_EQ(listed, expected);
  }
  EXPECT_EQ(folders, 7);
}

TEST(Ros2Layouts, FilesAndMessagesCompressedWithZstdReadAsTheSameFrames) {
  const test::TempDir dir("ros2_compressed");
  const fs::path plain = write_ros2_export(dir.path());
  const std::string mcap = read_bytes(plain / "b_0.mcap");
  const std::vector<RecordedFrame> expected = frames_of(plain);
  ASSERT_EQ(expected.size(), 3u);

  const fs::path file_mode = dir.path() / "file_mode";
  fs::create_directories(file_mode);
  write_bytes(file_mode / "b_0.mcap.zstd", detail::mcap_compress(detail::McapCompression::kZstd, mcap));
  write_metadata(file_mode, {"b_0.mcap.zstd"}, "FILE", "zstd");
  expect_same_frames(frames_of(file_mode), expected);

  const fs::path message_mode = dir.path() / "message_mode";
  fs::create_directories(message_mode);
  {
    detail::McapReader reader((plain / "b_0.mcap").string());
    detail::McapWriter writer((message_mode / "b_0.mcap").string(), detail::McapCompression::kNone, "ros2", "test");
    std::map<std::uint16_t, std::uint16_t> schemas, channels;
    detail::McapRecord r;
    while (reader.next(r)) {
      if (r.kind == detail::McapRecord::kSchema) {
        schemas[r.schema.id] = writer.add_schema(r.schema.name, r.schema.encoding, r.schema.data);
      } else if (r.kind == detail::McapRecord::kChannel) {
        channels[r.channel.id] =
            writer.add_channel(schemas.at(r.channel.schema_id), r.channel.topic, r.channel.message_encoding, {});
      } else if (r.kind == detail::McapRecord::kMessage) {
        const std::string compressed =
            detail::mcap_compress(detail::McapCompression::kZstd, std::string(r.data.begin(), r.data.end()));
        writer.write_message(channels.at(r.channel_id), r.log_time_ns, r.publish_time_ns,
                             std::vector<std::uint8_t>(compressed.begin(), compressed.end()));
      }
    }
    writer.close();
  }
  write_metadata(message_mode, {"b_0.mcap"}, "MESSAGE", "zstd");
  expect_same_frames(frames_of(message_mode), expected);

  // Another compressor, or a file that is not zstd: refused with the reason.
  write_metadata(file_mode, {"b_0.mcap.zstd"}, "FILE", "lz4");
  EXPECT_NE(error_of(file_mode.string()).find("compression_format 'lz4' is not read"), std::string::npos);
  write_bytes(file_mode / "b_0.mcap.zstd", mcap);
  write_metadata(file_mode, {"b_0.mcap.zstd"}, "FILE", "zstd");
  EXPECT_NE(error_of(file_mode.string()).find("not zstd"), std::string::npos) << error_of(file_mode.string());
}

TEST(Ros2Layouts, SplitBagsAreOneRecordingAndAFileCutShortBeforeTheLastIsRefused) {
  const test::TempDir dir("ros2_split");
  const fs::path plain = write_ros2_export(dir.path());
  const std::string mcap = read_bytes(plain / "b_0.mcap");
  const fs::path split = dir.path() / "split";
  fs::create_directories(split);
  // Cut inside the chunk (the data section ends where the summary begins, after the chunk and its indexes).
  write_bytes(split / "b_0.mcap", mcap.substr(0, 200));
  write_bytes(split / "b_1.mcap", mcap);
  write_metadata(split, {"b_0.mcap", "b_1.mcap"});
  const std::string error = error_of(split.string());
  EXPECT_NE(error.find("b_0.mcap: cut short, and it is not the split bag's last file"), std::string::npos) << error;

  // The last file cut short (a recorder stopped hard): read up to its last whole record.
  write_metadata(split, {"b_1.mcap", "b_0.mcap"});
  testing::internal::CaptureStderr();
  EXPECT_NO_THROW(list_recording(split.string()));
  EXPECT_NE(list_recording(split.string()).warnings.size(), 0u);
  testing::internal::GetCapturedStderr();

  // Without metadata.yaml the files are read in natural order (b_2 before b_10); newer metadata versions warn.
  const fs::path bare = dir.path() / "bare";
  fs::create_directories(bare);
  write_bytes(bare / "b_10.mcap", mcap);
  write_bytes(bare / "b_2.mcap", mcap);
  const RecordingContents contents = list_recording(bare.string());
  ASSERT_EQ(contents.files.size(), 2u);
  EXPECT_EQ(fs::path(contents.files[0]).filename(), "b_2.mcap");
  write_metadata(bare, {"b_2.mcap"}, "", "", 10);
  const RecordingContents newer = list_recording(bare.string());
  ASSERT_EQ(newer.warnings.size(), 1u);
  EXPECT_NE(newer.warnings[0].find("metadata version 10 is newer than 9"), std::string::npos);
  write_metadata(bare, {"b_2.mcap", "b_3.mcap"});
  EXPECT_NE(error_of(bare.string()).find("names b_3.mcap, which is missing"), std::string::npos);
}

}  // namespace
}  // namespace stvl::recording

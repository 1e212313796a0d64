// What both export formats share: the format, compression and topic choices, the costs as occupancy, and the
// writer for a format.
#include <filesystem>
#include <stdexcept>

#include "common/enum_names.hpp"
#include "recording/bag_writer.hpp"
#include "recording/detail.hpp"

namespace stvl::recording {

namespace {
constexpr EnumName<BagCompression> kCompressionNames[] = {{BagCompression::kNone, "none"},
                                                          {BagCompression::kBz2, "bz2"},
                                                          {BagCompression::kLz4, "lz4"},
                                                          {BagCompression::kZstd, "zstd"}};
}  // namespace

BagCompression parse_bag_compression(const std::string& name) {
  return parse_enum(name, kCompressionNames, "bag compression");
}

std::string to_string(BagCompression compression) { return enum_name(compression, kCompressionNames); }

std::vector<std::int8_t> occupancy_values(const mapping::Costmap2D& costmap) {
  std::vector<std::int8_t> data(costmap.cells.size());
  for (std::size_t i = 0; i < data.size(); ++i) {
    const int c = costmap.cells[i];
    data[i] = static_cast<std::int8_t>(c == mapping::kCostUnknown  ? -1
                                       : c == mapping::kCostLethal ? 100
                                       : c == 253                  ? 99
                                       : c == mapping::kCostFree   ? 0
                                                                   : 1 + 97 * (c - 1) / 251);
  }
  return data;
}

BagFormat parse_bag_format(const std::string& name, const std::string& path) {
  if (name == "ros1") return BagFormat::kRos1;
  if (name == "ros2") return BagFormat::kRos2;
  if (!name.empty()) throw std::invalid_argument("bag format must be ros1 or ros2, got '" + name + "'");
  const std::string ext = std::filesystem::path(path).extension().string();
  return ext == ".mcap" ? BagFormat::kRos2 : BagFormat::kRos1;
}

std::string ros2_bag_folder(const std::string& path) {
  std::string folder = path;
  while (folder.size() > 1 && folder.back() == '/') folder.pop_back();
  const std::filesystem::path p(folder);
  if (p.extension() == ".mcap" || p.extension() == ".bag") return (p.parent_path() / p.stem()).string();
  return folder;
}

namespace {
// '*' matches any run of characters.
bool glob_match(const char* pattern, const char* text) {
  if (*pattern == '\0') return *text == '\0';
  if (*pattern == '*') return glob_match(pattern + 1, text) || (*text && glob_match(pattern, text + 1));
  return *text == *pattern && glob_match(pattern + 1, text + 1);
}
const char* const kDefaultTopics[] = {"/clock",
                                      "/tf",
                                      "/tf_static",
                                      "/odom",
                                      "/ground_truth/*",
                                      "/*/depth/image_rect_raw",
                                      "/*/depth/camera_info",
                                      "/stvl/*",
                                      "/plan",
                                      "/cmd_vel",
                                      "/local_costmap/costmap",
                                      "/global_costmap/costmap"};
}  // namespace

BagTopics::BagTopics(const std::string& spec) : spec_(spec.empty() ? "all" : spec) {
  std::size_t start = 0;
  while (start <= spec_.size()) {
    std::size_t end = spec_.find(',', start);
    if (end == std::string::npos) end = spec_.size();
    std::string item = spec_.substr(start, end - start);
    item.erase(0, item.find_first_not_of(" \t"));
    item.erase(item.find_last_not_of(" \t") + 1);
    if (item == "all") {
      patterns_.push_back("*");
    } else if (item == "default") {
      patterns_.insert(patterns_.end(), std::begin(kDefaultTopics), std::end(kDefaultTopics));
    } else if (!item.empty() && item[0] == '/') {
      patterns_.push_back(item);
    } else {
      throw std::invalid_argument("--bag-topics: '" + item +
                                  "' is neither a topic (/name, '*' as a wildcard) nor all or default");
    }
    start = end + 1;
  }
}

bool BagTopics::wants(const std::string& topic) const {
  for (const auto& p : patterns_)
    if (glob_match(p.c_str(), topic.c_str())) return true;
  return false;
}

std::unique_ptr<BagSink> make_bag_writer(const std::string& path, BagFormat format, BagCompression compression) {
  if (format == BagFormat::kRos1) return std::make_unique<BagWriter>(path, compression);
  return detail::make_ros2_bag_writer(ros2_bag_folder(path), compression);
}

}  // namespace stvl::recording

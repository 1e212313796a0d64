#include "recording/ros2_source.hpp"

#include <sqlite3.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <stdexcept>

#include "recording/mcap.hpp"
#include "recording/ros2_msgs.hpp"

namespace stvl::recording::detail {
namespace {

namespace fs = std::filesystem;

std::string magic_of(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char m[16] = {};
  in.read(m, 16);
  return std::string(m, static_cast<std::size_t>(in.gcount()));
}

void check_type(const std::string& where, const std::string& topic, const std::string& type) {
  static const std::regex kType(R"(^[A-Za-z][A-Za-z0-9_]*/msg/[A-Za-z][A-Za-z0-9_]*$)");
  if (!std::regex_match(type, kType))
    throw std::invalid_argument(where + ": topic " + topic + " has unknown type '" + type +
                                "' (expected pkg/msg/Type)");
}

// The storage files a rosbag2 folder's metadata.yaml names; throws for FILE compression or a missing file.
std::vector<std::string> files_named_in_metadata(const std::string& path, const fs::path& yaml) {
  std::vector<std::string> paths;
  std::error_code ec;
  YAML::Node info;
  try {
    info = YAML::LoadFile(yaml.string())["rosbag2_bagfile_information"];
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(yaml.string() + ": not YAML: " + e.what());
  }
  if (!info) throw std::invalid_argument(yaml.string() + ": no rosbag2_bagfile_information");
  if (info["compression_mode"] && info["compression_mode"].as<std::string>() == "FILE")
    throw std::invalid_argument(yaml.string() +
                                ": compression_mode FILE (whole files compressed) is not read; "
                                "decompress the files first (zstd -d) and drop the mode from metadata.yaml");
  if (const auto files = info["relative_file_paths"])
    for (const auto& f : files) paths.push_back((fs::path(path) / f.as<std::string>()).string());
  for (const auto& p : paths)
    if (!fs::exists(p, ec))
      throw std::invalid_argument(yaml.string() + " names " + fs::path(p).filename().string() +
                                  ", which is missing from " + path);
  return paths;
}

// The storage files of `path`: itself, or a folder's files as its metadata.yaml names them (without one, its
// .mcap and .db3 files in name order).
std::vector<std::string> storage_files(const std::string& path) {
  std::error_code ec;
  if (!fs::is_directory(path, ec)) return {path};
  std::vector<std::string> paths;
  const fs::path yaml = fs::path(path) / "metadata.yaml";
  if (fs::exists(yaml, ec)) {
    paths = files_named_in_metadata(path, yaml);
  } else {
    for (const auto& e : fs::directory_iterator(path, ec))
      if (e.path().extension() == ".mcap" || e.path().extension() == ".db3") paths.push_back(e.path().string());
    std::sort(paths.begin(), paths.end());
  }
  if (paths.empty()) throw std::invalid_argument(path + ": a rosbag2 folder without .mcap or .db3 files");
  return paths;
}

struct Statement {
  sqlite3_stmt* s = nullptr;
  Statement(sqlite3* db, const std::string& sql, const std::string& where) {
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr) != SQLITE_OK)
      throw std::invalid_argument(where + ": " + sqlite3_errmsg(db) + " (in: " + sql + ")");
  }
  ~Statement() { sqlite3_finalize(s); }
};

}  // namespace

struct Ros2Source::File {
  std::string path;
  bool mcap = true;
  sqlite3* db = nullptr;
  std::map<std::int64_t, std::string> topic_by_id;  // db3
  ~File() {
    if (db) sqlite3_close(db);
  }
};

Ros2Source::Ros2Source(const std::string& path) : path_(path) {
  for (const auto& p : storage_files(path)) {
    auto file = std::make_unique<File>();
    file->path = p;
    const std::string magic = magic_of(p);
    std::error_code ec;
    if (magic.compare(0, 15, "SQLite format 3") == 0) {
      open_db3(*file);
      format_ = "rosbag2 (sqlite3)";
    } else if (magic.compare(0, 5, "\x89MCAP") == 0) {
      format_ = "rosbag2 (mcap)";
    } else if (!fs::exists(p, ec)) {
      throw std::invalid_argument(p + ": no such file");
    } else {
      throw std::invalid_argument(p + ": neither MCAP (bad magic: no \\x89MCAP0\\r\\n) nor a rosbag2 sqlite3 file");
    }
    files_.push_back(std::move(file));
  }
  // A first pass: topics and counts, every record checked.
  for (auto& [name, t] : topics_) t.count = 0;
  scan(nullptr, [](const Ros2Topic&, std::int64_t, const std::uint8_t*, std::size_t) { return true; });
  counted_ = true;
}

Ros2Source::~Ros2Source() = default;

void Ros2Source::open_db3(File& file) {
  const std::string& p = file.path;
  file.mcap = false;
  if (sqlite3_open_v2(p.c_str(), &file.db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK)
    throw std::invalid_argument(p + ": cannot open as sqlite3: " + sqlite3_errmsg(file.db));
  std::set<std::string> tables;
  {
    Statement st(file.db, "SELECT name FROM sqlite_master WHERE type='table'", p);
    while (sqlite3_step(st.s) == SQLITE_ROW) tables.insert(reinterpret_cast<const char*>(sqlite3_column_text(st.s, 0)));
  }
  for (const char* t : {"topics", "messages"})
    if (!tables.count(t)) throw std::invalid_argument(p + ": not a rosbag2 sqlite3 file: no " + t + " table");
  Statement st(file.db, "SELECT id, name, type, serialization_format FROM topics", p);
  while (sqlite3_step(st.s) == SQLITE_ROW) {
    const auto text = [&](int i) {
      const auto* c = sqlite3_column_text(st.s, i);
      return c ? std::string(reinterpret_cast<const char*>(c)) : std::string();
    };
    Ros2Topic t{text(1), text(2), 0};
    check_type(p, t.name, t.type);
    if (text(3) != "cdr")
      throw std::invalid_argument(p + ": topic " + t.name + " is serialized as '" + text(3) + "', expected cdr");
    file.topic_by_id[sqlite3_column_int64(st.s, 0)] = t.name;
    topics_.emplace(t.name, t);
  }
  if (tables.count("message_definitions")) {  // Jazzy: the definitions beside the messages
    Statement d(file.db, "SELECT topic_type, encoding, encoded_message_definition FROM message_definitions", p);
    while (sqlite3_step(d.s) == SQLITE_ROW) {
      const auto* type = sqlite3_column_text(d.s, 0);
      const auto* enc = sqlite3_column_text(d.s, 1);
      const auto* def = sqlite3_column_text(d.s, 2);
      if (type && enc && def && std::string(reinterpret_cast<const char*>(enc)) == "ros2msg")
        check_ros2_schema(reinterpret_cast<const char*>(type), reinterpret_cast<const char*>(def), p);
    }
  }
}

void Ros2Source::scan(const std::string* topic, const Visit& f) {
  const bool counting = topic == nullptr && !counted_;
  for (auto& file : files_)
    if (!(file->mcap ? scan_mcap(*file, topic, f, counting) : scan_db3(*file, topic, f, counting))) return;
}

bool Ros2Source::scan_db3(File& file, const std::string* topic, const Visit& f, bool counting) {
  Statement st(file.db,
               std::string("SELECT topic_id, timestamp, data FROM messages") + (topic ? " WHERE topic_id = ?" : "") +
                   " ORDER BY timestamp, id",
               file.path);
  if (topic) {
    std::int64_t id = -1;
    for (const auto& [i, name] : file.topic_by_id)
      if (name == *topic) id = i;
    sqlite3_bind_int64(st.s, 1, id);
  }
  int rc;
  while ((rc = sqlite3_step(st.s)) == SQLITE_ROW) {
    const auto it = file.topic_by_id.find(sqlite3_column_int64(st.s, 0));
    if (it == file.topic_by_id.end())
      throw std::invalid_argument(file.path + ": a message of topic id " +
                                  std::to_string(sqlite3_column_int64(st.s, 0)) + ", which topics lacks");
    auto& t = topics_.at(it->second);
    if (counting) ++t.count;
    const auto* data = static_cast<const std::uint8_t*>(sqlite3_column_blob(st.s, 2));
    if (!f(t, sqlite3_column_int64(st.s, 1), data, static_cast<std::size_t>(sqlite3_column_bytes(st.s, 2))))
      return false;
  }
  if (rc != SQLITE_DONE) throw std::invalid_argument(file.path + ": " + sqlite3_errmsg(file.db));
  return true;
}

bool Ros2Source::scan_mcap(File& file, const std::string* topic, const Visit& f, bool counting) {
  McapReader reader(file.path);
  std::map<std::uint16_t, McapSchema> schemas;
  std::map<std::uint16_t, std::string> channels;
  McapRecord r;
  while (reader.next(r)) {
    if (r.kind == McapRecord::kSchema) {
      schemas[r.schema.id] = r.schema;
    } else if (r.kind == McapRecord::kChannel) {
      add_mcap_channel(file, r.channel, schemas, channels);
    } else if (r.kind == McapRecord::kMessage) {
      const auto c = channels.find(r.channel_id);
      if (c == channels.end())
        throw std::invalid_argument(file.path + ": a message on channel " + std::to_string(r.channel_id) +
                                    ", which was never defined");
      if (topic && c->second != *topic) continue;
      auto& t = topics_.at(c->second);
      if (counting) ++t.count;
      if (!f(t, static_cast<std::int64_t>(r.log_time_ns), r.data.data(), r.data.size())) return false;
    }
  }
  if (!reader.truncation_warning().empty() &&
      std::find(warnings_.begin(), warnings_.end(), reader.truncation_warning()) == warnings_.end())
    warnings_.push_back(reader.truncation_warning());
  return true;
}

void Ros2Source::add_mcap_channel(const File& file, const McapChannel& channel,
                                  const std::map<std::uint16_t, McapSchema>& schemas,
                                  std::map<std::uint16_t, std::string>& channels) {
  const std::string where = file.path + ": channel " + channel.topic;
  const auto s = schemas.find(channel.schema_id);
  if (s == schemas.end())
    throw std::invalid_argument(where + ": no schema (id " + std::to_string(channel.schema_id) + ")");
  if (channel.message_encoding != "cdr")
    throw std::invalid_argument(where + ": message encoding '" + channel.message_encoding + "', expected cdr");
  if (s->second.encoding != "ros2msg")
    throw std::invalid_argument(where + ": schema encoding '" + s->second.encoding + "', expected ros2msg");
  check_type(file.path, channel.topic, s->second.name);
  check_ros2_schema(s->second.name, s->second.data, where);
  auto [it, added] = topics_.emplace(channel.topic, Ros2Topic{channel.topic, s->second.name, 0});
  if (!added && it->second.type != s->second.name)
    throw std::invalid_argument(where + ": recorded as " + it->second.type + " and as " + s->second.name);
  channels[channel.id] = channel.topic;
}

namespace {
// The simplest cursor: messages of the topic gathered a batch at a time by a scan that resumes by index.
class ScanCursor final : public Ros2Source::Cursor {
 public:
  ScanCursor(Ros2Source& source, std::string topic) : source_(source), topic_(std::move(topic)) {}
  bool next(std::int64_t& time_ns, std::vector<std::uint8_t>& data) override {
    if (batch_at_ == batch_.size()) {
      batch_.clear(), batch_at_ = 0;
      std::size_t seen = 0, bytes = 0;
      source_.scan(&topic_, [&](const Ros2Topic&, std::int64_t t, const std::uint8_t* d, std::size_t n) {
        if (seen++ < consumed_) return true;
        batch_.emplace_back(t, std::vector<std::uint8_t>(d, d + n));
        bytes += n;
        return bytes < (64u << 20);
      });
      if (batch_.empty()) return false;
    }
    time_ns = batch_[batch_at_].first;
    data.swap(batch_[batch_at_].second);
    ++batch_at_, ++consumed_;
    return true;
  }

 private:
  Ros2Source& source_;
  std::string topic_;
  std::vector<std::pair<std::int64_t, std::vector<std::uint8_t>>> batch_;
  std::size_t batch_at_ = 0, consumed_ = 0;
};
}  // namespace

std::unique_ptr<Ros2Source::Cursor> Ros2Source::cursor(const std::string& topic) {
  return std::make_unique<ScanCursor>(*this, topic);
}

}  // namespace stvl::recording::detail

#include "recording/ros2_source.hpp"

#include <sqlite3.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>
#include <zstd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>

#include "recording/mcap.hpp"

namespace stvl::recording::detail {
namespace {

namespace fs = std::filesystem;

std::string magic_of(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char m[16] = {};
  in.read(m, 16);
  return std::string(m, static_cast<std::size_t>(in.gcount()));
}

// Names in the order a person numbers them: "b_2.db3" before "b_10.db3".
bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) && std::isdigit(static_cast<unsigned char>(b[j]))) {
      std::size_t i_end = i, j_end = j;
      while (i_end < a.size() && std::isdigit(static_cast<unsigned char>(a[i_end]))) ++i_end;
      while (j_end < b.size() && std::isdigit(static_cast<unsigned char>(b[j_end]))) ++j_end;
      const std::string x = a.substr(i, i_end - i), y = b.substr(j, j_end - j);
      const std::string xs = x.substr(std::min(x.find_first_not_of('0'), x.size()));
      const std::string ys = y.substr(std::min(y.find_first_not_of('0'), y.size()));
      if (xs.size() != ys.size()) return xs.size() < ys.size();
      if (xs != ys) return xs < ys;
      i = i_end, j = j_end;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i, ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

// What a rosbag2 folder holds: its storage files in reading order and how they are compressed.
struct Layout {
  std::vector<std::string> files;
  bool file_compression = false, message_compression = false;
  std::vector<std::string> warnings;
  std::vector<Ros2Topic> topics;  // as metadata.yaml lists them (a topic without messages is in no file)
};

// The storage files a rosbag2 folder's metadata.yaml names, and its compression; throws for a missing file or a
// compression that is not zstd.
Layout layout_from_metadata(const std::string& path, const fs::path& yaml) {
  Layout layout;
  std::error_code ec;
  YAML::Node info;
  try {
    info = YAML::LoadFile(yaml.string())["rosbag2_bagfile_information"];
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(yaml.string() + ": not YAML: " + e.what());
  }
  if (!info) throw std::invalid_argument(yaml.string() + ": no rosbag2_bagfile_information");
  const auto text = [&](const char* key) {
    try {
      return info[key] && info[key].IsScalar() ? info[key].as<std::string>() : std::string();
    } catch (const YAML::Exception&) {
      return std::string();
    }
  };
  const std::string version = text("version");
  if (!version.empty() && version.size() < 6 && version.find_first_not_of("0123456789") == std::string::npos &&
      std::stoi(version) > 9)
    layout.warnings.push_back(yaml.string() + ": metadata version " + version +
                              " is newer than 9, the newest known; read as version 9");
  const std::string mode = text("compression_mode"), format = text("compression_format");
  if (mode == "FILE" || mode == "MESSAGE") {
    if (format != "zstd")
      throw std::invalid_argument(yaml.string() + ": compression_mode " + mode + " with compression_format '" + format +
                                  "' is not read (rosbag2 compresses with zstd only)");
    (mode == "FILE" ? layout.file_compression : layout.message_compression) = true;
  } else if (!mode.empty() && mode != "NONE") {
    throw std::invalid_argument(yaml.string() + ": unknown compression_mode '" + mode + "' (expected FILE or MESSAGE)");
  }
  const auto topics = info["topics_with_message_count"];
  if (topics && topics.IsSequence())
    for (const auto& t : topics) {
      const auto m = t["topic_metadata"];
      if (!m || !m["name"] || !m["name"].IsScalar()) continue;
      const auto scalar = [&](const char* key) {
        return m[key] && m[key].IsScalar() ? m[key].as<std::string>() : std::string();
      };
      layout.topics.push_back(Ros2Topic{scalar("name"), scalar("type"), 0, scalar("serialization_format"), "", ""});
    }
  const auto files = info["relative_file_paths"];
  if (files && files.IsSequence())
    for (const auto& f : files) layout.files.push_back((fs::path(path) / f.as<std::string>()).string());
  for (auto& p : layout.files) {
    // FILE compression: the metadata names x.mcap.zstd (or, before the files were compressed, x.mcap).
    if (layout.file_compression && !fs::exists(p, ec) && fs::exists(p + ".zstd", ec)) p += ".zstd";
    if (!fs::exists(p, ec))
      throw std::invalid_argument(yaml.string() + " names " + fs::path(p).filename().string() +
                                  ", which is missing from " + path);
  }
  return layout;
}

// The storage files of `path`: itself, or a folder's files as its metadata.yaml names them (without one, its
// .mcap and .db3 files in natural name order).
Layout storage_layout(const std::string& path) {
  std::error_code ec;
  Layout layout;
  if (!fs::is_directory(path, ec)) {
    layout.files.push_back(path);
    return layout;
  }
  const fs::path yaml = fs::path(path) / "metadata.yaml";
  if (fs::exists(yaml, ec)) {
    layout = layout_from_metadata(path, yaml);
  } else {
    for (const auto& e : fs::directory_iterator(path, ec))
      if (e.path().extension() == ".mcap" || e.path().extension() == ".db3") layout.files.push_back(e.path().string());
    std::sort(layout.files.begin(), layout.files.end(), natural_less);
  }
  if (layout.files.empty()) throw std::invalid_argument(path + ": a rosbag2 folder without .mcap or .db3 files");
  return layout;
}

// A zstd-compressed storage file (compression_mode FILE) decompressed into a new temporary file; its path.
std::string decompress_to_temporary(const std::string& path) {
  static std::atomic<int> counter{0};
  std::error_code ec;
  const fs::path out_path =
      fs::temp_directory_path(ec) / ("stvl-rosbag2-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) +
                                     "-" + fs::path(path).stem().filename().string());
  std::ifstream in(path, std::ios::binary);
  std::ofstream out(out_path, std::ios::binary | std::ios::trunc);
  if (!in || !out) throw std::invalid_argument(path + ": cannot decompress into " + out_path.string());
  std::unique_ptr<ZSTD_DStream, decltype(&ZSTD_freeDStream)> stream(ZSTD_createDStream(), ZSTD_freeDStream);
  ZSTD_initDStream(stream.get());
  std::vector<char> in_buffer(ZSTD_DStreamInSize()), out_buffer(ZSTD_DStreamOutSize());
  std::size_t last = 0;
  while (in.read(in_buffer.data(), static_cast<std::streamsize>(in_buffer.size())) || in.gcount() > 0) {
    ZSTD_inBuffer input{in_buffer.data(), static_cast<std::size_t>(in.gcount()), 0};
    while (input.pos < input.size) {
      ZSTD_outBuffer output{out_buffer.data(), out_buffer.size(), 0};
      last = ZSTD_decompressStream(stream.get(), &output, &input);
      if (ZSTD_isError(last)) {
        fs::remove(out_path, ec);
        throw std::invalid_argument(path + ": not zstd (compression_mode FILE): " + ZSTD_getErrorName(last));
      }
      out.write(out_buffer.data(), static_cast<std::streamsize>(output.pos));
    }
  }
  out.close();
  if (last != 0 || !out) {
    fs::remove(out_path, ec);
    throw std::invalid_argument(path + ": zstd file cut short (compression_mode FILE)");
  }
  return out_path.string();
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
  std::string path;       // as named (what errors say)
  std::string read_path;  // what is read: path, or its decompressed temporary copy
  bool mcap = true, last = true;
  sqlite3* db = nullptr;
  std::map<std::int64_t, std::string> topic_by_id;  // db3
  ~File() {
    if (db) sqlite3_close(db);
    std::error_code ec;
    if (read_path != path) fs::remove(read_path, ec);
  }
};

Ros2Source::Ros2Source(const std::string& path) : path_(path) {
  Layout layout = storage_layout(path);
  warnings_ = layout.warnings;
  message_compression_ = layout.message_compression;
  for (const auto& p : layout.files) {
    auto file = std::make_unique<File>();
    file->path = file->read_path = p;
    file->last = &p == &layout.files.back();
    std::error_code ec;
    if (!fs::exists(p, ec)) throw std::invalid_argument(p + ": no such file");
    if (layout.file_compression || fs::path(p).extension() == ".zstd") file->read_path = decompress_to_temporary(p);
    const std::string magic = magic_of(file->read_path);
    if (magic.compare(0, 15, "SQLite format 3") == 0) {
      open_db3(*file);
      format_ = "rosbag2 (sqlite3)";
    } else if (magic.compare(0, 5, "\x89MCAP") == 0) {
      format_ = "rosbag2 (mcap)";
    } else {
      throw std::invalid_argument(p + ": neither MCAP (bad magic: no \\x89MCAP0\\r\\n) nor a rosbag2 sqlite3 file");
    }
    file_paths_.push_back(p);
    files_.push_back(std::move(file));
  }
  // A first pass: topics and counts, every record checked.
  for (auto& [name, t] : topics_) t.count = 0;
  scan(nullptr, [](const Ros2Topic&, std::int64_t, const std::uint8_t*, std::size_t) { return true; });
  counted_ = true;
  for (const auto& t : layout.topics) topics_.emplace(t.name, t);
}

Ros2Source::~Ros2Source() = default;

void Ros2Source::open_db3(File& file) {
  const std::string& p = file.path;
  file.mcap = false;
  if (sqlite3_open_v2(file.read_path.c_str(), &file.db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK)
    throw std::invalid_argument(p + ": cannot open as sqlite3: " + sqlite3_errmsg(file.db));
  std::set<std::string> tables;
  {
    Statement st(file.db, "SELECT name FROM sqlite_master WHERE type='table'", p);
    while (sqlite3_step(st.s) == SQLITE_ROW) tables.insert(reinterpret_cast<const char*>(sqlite3_column_text(st.s, 0)));
  }
  for (const char* t : {"topics", "messages"})
    if (!tables.count(t)) throw std::invalid_argument(p + ": not a rosbag2 sqlite3 file: no " + t + " table");
  std::map<std::string, std::pair<std::string, std::string>> definitions;  // type -> encoding, text
  if (tables.count("message_definitions")) {                               // Jazzy: the definitions beside the messages
    Statement d(file.db, "SELECT topic_type, encoding, encoded_message_definition FROM message_definitions", p);
    while (sqlite3_step(d.s) == SQLITE_ROW) {
      const auto text = [&](int i) {
        const auto* c = sqlite3_column_text(d.s, i);
        return c ? std::string(reinterpret_cast<const char*>(c)) : std::string();
      };
      // rosbag2 writes encoding "unknown" with an empty text for a type it found no definition of.
      if (text(1) != "unknown" && !text(2).empty()) definitions[text(0)] = {text(1), text(2)};
    }
  }
  Statement st(file.db, "SELECT id, name, type, serialization_format FROM topics", p);
  while (sqlite3_step(st.s) == SQLITE_ROW) {
    const auto text = [&](int i) {
      const auto* c = sqlite3_column_text(st.s, i);
      return c ? std::string(reinterpret_cast<const char*>(c)) : std::string();
    };
    Ros2Topic t{text(1), text(2), 0, text(3), "", ""};
    const auto d = definitions.find(t.type);
    if (d != definitions.end()) t.schema_encoding = d->second.first, t.schema = d->second.second;
    file.topic_by_id[sqlite3_column_int64(st.s, 0)] = t.name;
    add_topic(p, t);
  }
}

void Ros2Source::add_topic(const std::string& where, Ros2Topic topic) {
  const auto [it, added] = topics_.emplace(topic.name, topic);
  if (added || it->second.type == topic.type) return;
  const std::string warning = where + ": topic " + topic.name + " is recorded as " + topic.type + " here and as " +
                              it->second.type + " before; read as " + it->second.type;
  if (std::find(warnings_.begin(), warnings_.end(), warning) == warnings_.end()) warnings_.push_back(warning);
}

void Ros2Source::decompress_message(const std::uint8_t*& data, std::size_t& size, const std::string& where) {
  const unsigned long long frame_size = ZSTD_getFrameContentSize(data, size);
  if (frame_size == ZSTD_CONTENTSIZE_ERROR || frame_size == ZSTD_CONTENTSIZE_UNKNOWN || frame_size > (1ull << 32))
    throw std::invalid_argument(where + ": a message that is not a zstd frame (compression_mode MESSAGE)");
  buffer_.resize(frame_size);
  const std::size_t got = ZSTD_decompress(buffer_.data(), buffer_.size(), data, size);
  if (ZSTD_isError(got) || got != frame_size)
    throw std::invalid_argument(where + ": a message whose zstd data is corrupt (compression_mode MESSAGE)");
  data = buffer_.data(), size = buffer_.size();
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
    auto size = static_cast<std::size_t>(sqlite3_column_bytes(st.s, 2));
    if (message_compression_) decompress_message(data, size, file.path + ": " + t.name);
    if (!f(t, sqlite3_column_int64(st.s, 1), data, size)) return false;
  }
  if (rc != SQLITE_DONE) throw std::invalid_argument(file.path + ": " + sqlite3_errmsg(file.db));
  return true;
}

bool Ros2Source::scan_mcap(File& file, const std::string* topic, const Visit& f, bool counting) {
  McapReader reader(file.read_path);
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
      const std::uint8_t* data = r.data.data();
      std::size_t size = r.data.size();
      if (message_compression_) decompress_message(data, size, file.path + ": " + t.name);
      if (!f(t, static_cast<std::int64_t>(r.log_time_ns), data, size)) return false;
    }
  }
  if (!reader.truncation_warning().empty() && !file.last)
    throw std::invalid_argument(file.path + ": cut short, and it is not the split bag's last file (" +
                                reader.truncation_warning() + ")");
  if (!reader.truncation_warning().empty() &&
      std::find(warnings_.begin(), warnings_.end(), reader.truncation_warning()) == warnings_.end())
    warnings_.push_back(reader.truncation_warning());
  return true;
}

void Ros2Source::add_mcap_channel(const File& file, const McapChannel& channel,
                                  const std::map<std::uint16_t, McapSchema>& schemas,
                                  std::map<std::uint16_t, std::string>& channels) {
  Ros2Topic t{channel.topic, "", 0, channel.message_encoding, "", ""};
  if (channel.schema_id != 0) {  // 0: a channel without schema (MCAP allows it, e.g. for json)
    const auto s = schemas.find(channel.schema_id);
    if (s == schemas.end())
      throw std::invalid_argument(file.path + ": channel " + channel.topic + ": no schema (id " +
                                  std::to_string(channel.schema_id) + ")");
    t.type = s->second.name, t.schema_encoding = s->second.encoding, t.schema = s->second.data;
  }
  add_topic(file.path, t);
  channels[channel.id] = channel.topic;
}

// One topic's messages in storage order, each file read once: an MCAP file record by record, a .db3 file by one
// statement stepped as frames are asked for.
class StreamCursor final : public Ros2Source::Cursor {
 public:
  StreamCursor(Ros2Source& source, std::string topic) : source_(source), topic_(std::move(topic)) {}
  ~StreamCursor() override { sqlite3_finalize(statement_); }

  bool next(std::int64_t& time_ns, std::vector<std::uint8_t>& data) override {
    while (file_ < source_.files_.size()) {
      Ros2Source::File& file = *source_.files_[file_];
      if (file.mcap ? next_mcap(file, time_ns, data) : next_db3(file, time_ns, data)) return true;
      ++file_;
    }
    return false;
  }

 private:
  void deliver(const Ros2Source::File& file, std::int64_t t_ns, const std::uint8_t* bytes, std::size_t size,
               std::int64_t& time_ns, std::vector<std::uint8_t>& data) {
    if (source_.message_compression_) source_.decompress_message(bytes, size, file.path + ": " + topic_);
    time_ns = t_ns;
    data.assign(bytes, bytes + size);
  }

  bool next_mcap(const Ros2Source::File& file, std::int64_t& time_ns, std::vector<std::uint8_t>& data) {
    if (!reader_) reader_ = std::make_unique<McapReader>(file.read_path), channels_.clear();
    while (reader_->next(record_)) {
      if (record_.kind == McapRecord::kChannel && record_.channel.topic == topic_) channels_.insert(record_.channel.id);
      if (record_.kind != McapRecord::kMessage || !channels_.count(record_.channel_id)) continue;
      deliver(file, static_cast<std::int64_t>(record_.log_time_ns), record_.data.data(), record_.data.size(), time_ns,
              data);
      return true;
    }
    reader_.reset();
    return false;
  }

  bool next_db3(const Ros2Source::File& file, std::int64_t& time_ns, std::vector<std::uint8_t>& data) {
    if (!statement_) {
      const std::string sql = "SELECT timestamp, data FROM messages WHERE topic_id = ? ORDER BY timestamp, id";
      if (sqlite3_prepare_v2(file.db, sql.c_str(), -1, &statement_, nullptr) != SQLITE_OK)
        throw std::invalid_argument(file.path + ": " + sqlite3_errmsg(file.db) + " (in: " + sql + ")");
      std::int64_t id = -1;
      for (const auto& [i, name] : file.topic_by_id)
        if (name == topic_) id = i;
      sqlite3_bind_int64(statement_, 1, id);
    }
    const int rc = sqlite3_step(statement_);
    if (rc == SQLITE_ROW) {
      deliver(file, sqlite3_column_int64(statement_, 0),
              static_cast<const std::uint8_t*>(sqlite3_column_blob(statement_, 1)),
              static_cast<std::size_t>(sqlite3_column_bytes(statement_, 1)), time_ns, data);
      return true;
    }
    const std::string error = rc == SQLITE_DONE ? std::string() : sqlite3_errmsg(file.db);
    sqlite3_finalize(statement_);
    statement_ = nullptr;
    if (!error.empty()) throw std::invalid_argument(file.path + ": " + error);
    return false;
  }

  Ros2Source& source_;
  std::string topic_;
  std::size_t file_ = 0;
  std::unique_ptr<McapReader> reader_;
  McapRecord record_;
  std::set<std::uint16_t> channels_;  // the open MCAP file's channels of the topic
  sqlite3_stmt* statement_ = nullptr;
};

std::unique_ptr<Ros2Source::Cursor> Ros2Source::cursor(const std::string& topic) {
  return std::make_unique<StreamCursor>(*this, topic);
}

}  // namespace stvl::recording::detail

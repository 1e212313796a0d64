#pragma once
// rosbag2's storage (not part of the interface): a folder with metadata.yaml (versions 1 to 9) and its files (a
// split bag's in order; zstd-compressed files or messages), a folder of .mcap / .db3 files without one (as left
// before `ros2 bag reindex`), a bare .mcap or a bare .db3, as one stream of serialized messages in storage order.
// Every topic is listed whatever its type and encodings; nothing here decodes or checks a schema.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace stvl::recording::detail {

struct McapChannel;
struct McapSchema;
class StreamCursor;

struct Ros2Topic {
  std::string name, type;  // type as recorded ("sensor_msgs/msg/Image"; "" for an MCAP channel without schema)
  std::uint64_t count = 0;
  std::string message_encoding;  // "cdr", "json", ...
  std::string schema_encoding;   // "ros2msg", "ros2idl", "jsonschema", ...; "" where none is recorded
  std::string schema;            // the schema's text
};

class Ros2Source {
 public:
  // Throws std::invalid_argument("<path>: ...") for what is not rosbag2 storage: bad MCAP (magic, CRCs, lengths,
  // chunk compression, a message on an undefined channel), a .db3 without rosbag2's tables, a metadata.yaml
  // naming a missing file or a compression it cannot read, a split bag's file cut short before its last.
  explicit Ros2Source(const std::string& path);
  ~Ros2Source();
  const std::string& format() const { return format_; }                  // "rosbag2 (mcap)", "rosbag2 (sqlite3)"
  const std::vector<std::string>& files() const { return file_paths_; }  // the storage files, in reading order
  // Every message (topic == nullptr) or those of one topic, in storage order; f returns false to stop. The
  // topics are complete after the first full pass. Warnings (a file cut short) go to warnings().
  using Visit =
      std::function<bool(const Ros2Topic& topic, std::int64_t time_ns, const std::uint8_t* data, std::size_t size)>;
  void scan(const std::string* topic, const Visit& f);
  const std::map<std::string, Ros2Topic>& topics() const { return topics_; }
  const std::vector<std::string>& warnings() const { return warnings_; }

  // A pull cursor over one topic (the replay's depth frames), streaming through the files once: next() false at
  // the end.
  class Cursor {
   public:
    virtual ~Cursor() = default;
    virtual bool next(std::int64_t& time_ns, std::vector<std::uint8_t>& data) = 0;
  };
  std::unique_ptr<Cursor> cursor(const std::string& topic);

 private:
  friend class StreamCursor;
  struct File;
  void open_db3(File& file);  // its topics (with their definitions) into topics_, its tables checked
  void add_topic(const std::string& where, Ros2Topic topic);  // the first file's type of a topic stays
  // scan() over one file; false when f stopped it.
  bool scan_db3(File& file, const std::string* topic, const Visit& f, bool counting);
  bool scan_mcap(File& file, const std::string* topic, const Visit& f, bool counting);
  // An MCAP channel's topic into topics_ and channels (by channel id).
  void add_mcap_channel(const File& file, const McapChannel& channel,
                        const std::map<std::uint16_t, McapSchema>& schemas,
                        std::map<std::uint16_t, std::string>& channels);
  std::vector<std::unique_ptr<File>> files_;
  // compression_mode MESSAGE: the message's bytes zstd-decompressed into buffer_ (data and size then point there).
  void decompress_message(const std::uint8_t*& data, std::size_t& size, const std::string& where);
  std::string path_, format_;
  std::vector<std::string> file_paths_;
  bool message_compression_ = false;
  std::vector<std::uint8_t> buffer_;
  std::map<std::string, Ros2Topic> topics_;
  std::vector<std::string> warnings_;
  bool counted_ = false;  // the first pass counted the messages
};

}  // namespace stvl::recording::detail

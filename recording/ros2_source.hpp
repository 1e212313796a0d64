#pragma once
// rosbag2's storage (not part of the interface): a folder with metadata.yaml and its files, a bare .mcap or a
// bare .db3, as one stream of serialized messages in storage order.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace stvl::recording::detail {

struct McapChannel;
struct McapSchema;

struct Ros2Topic {
  std::string name, type;  // type as recorded ("sensor_msgs/msg/Image")
  std::uint64_t count = 0;
};

class Ros2Source {
 public:
  // Throws std::invalid_argument("<path>: ...") for what is not rosbag2 storage: bad MCAP (magic, CRCs, lengths,
  // compression, an unparsable schema, a message encoding other than cdr), a .db3 without rosbag2's tables or
  // with a type that is not pkg/msg/Name, a metadata.yaml naming a missing file.
  explicit Ros2Source(const std::string& path);
  ~Ros2Source();
  const std::string& format() const { return format_; }  // "rosbag2 (mcap)", "rosbag2 (sqlite3)"
  // Every message (topic == nullptr) or those of one topic, in storage order; f returns false to stop. The
  // topics are complete after the first full pass. Warnings (a file cut short) go to warnings().
  using Visit =
      std::function<bool(const Ros2Topic& topic, std::int64_t time_ns, const std::uint8_t* data, std::size_t size)>;
  void scan(const std::string* topic, const Visit& f);
  const std::map<std::string, Ros2Topic>& topics() const { return topics_; }
  const std::vector<std::string>& warnings() const { return warnings_; }

  // A pull cursor over one topic (the replay's depth frames): next() false at the end.
  class Cursor {
   public:
    virtual ~Cursor() = default;
    virtual bool next(std::int64_t& time_ns, std::vector<std::uint8_t>& data) = 0;
  };
  std::unique_ptr<Cursor> cursor(const std::string& topic);

 private:
  struct File;
  void open_db3(File& file);  // its topics into topics_, its tables and message definitions checked
  // scan() over one file; false when f stopped it.
  bool scan_db3(File& file, const std::string* topic, const Visit& f, bool counting);
  bool scan_mcap(File& file, const std::string* topic, const Visit& f, bool counting);
  // An MCAP channel's topic into topics_ and channels (by channel id), its schema checked.
  void add_mcap_channel(const File& file, const McapChannel& channel,
                        const std::map<std::uint16_t, McapSchema>& schemas,
                        std::map<std::uint16_t, std::string>& channels);
  std::vector<std::unique_ptr<File>> files_;
  std::string path_, format_;
  std::map<std::string, Ros2Topic> topics_;
  std::vector<std::string> warnings_;
  bool counted_ = false;  // the first pass counted the messages
};

}  // namespace stvl::recording::detail

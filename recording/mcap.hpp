#pragma once
// A small MCAP (https://mcap.dev/spec, major version 0) writer and reader (not part of the interface).
// Writer: schemas and channels inside the chunks that first use them, chunks compressed with zstd or lz4 (or
// not) followed by their message indexes, a data-end CRC, and a summary (schemas, channels, statistics, chunk
// and metadata indexes, summary offsets) with its CRC in the footer, so that indexed readers seek.
// Reader: the records in file order, chunks decompressed and CRC-checked, with or without a summary; a file
// cut short (no footer) is read up to its last whole record with a warning.
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace stvl::recording::detail {

enum class McapCompression { kNone, kZstd, kLz4 };

struct McapSchema {
  std::uint16_t id = 0;
  std::string name, encoding;
  std::string data;
};
struct McapChannel {
  std::uint16_t id = 0, schema_id = 0;
  std::string topic, message_encoding;
  std::map<std::string, std::string> metadata;
};

class McapWriter {
 public:
  // Throws std::runtime_error if the file cannot be created.
  McapWriter(const std::string& path, McapCompression compression, std::string profile, std::string library,
             std::size_t chunk_bytes = 4u << 20);
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  std::uint16_t add_schema(const std::string& name, const std::string& encoding, const std::string& data);
  std::uint16_t add_channel(std::uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                            const std::map<std::string, std::string>& metadata);
  void write_message(std::uint16_t channel_id, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
                     const std::vector<std::uint8_t>& data);
  // A Metadata record (rosbag2 writes one named "rosbag2").
  void write_metadata(const std::string& name, const std::map<std::string, std::string>& values);
  // Flushes the last chunk, writes the summary and the footer; throws std::runtime_error on a write error.
  void close();
  std::uint64_t bytes_written() const { return offset_; }
  std::uint64_t message_count() const { return message_count_; }

 private:
  void flush_chunk();
  void write(const std::string& bytes);
  struct State;
  std::unique_ptr<State> s_;
  std::uint64_t offset_ = 0, message_count_ = 0;
};

// One record of the data section as the reader hands it out.
struct McapRecord {
  enum Kind { kSchema, kChannel, kMessage, kMetadata } kind = kMessage;
  McapSchema schema;             // kSchema
  McapChannel channel;           // kChannel
  std::uint16_t channel_id = 0;  // kMessage
  std::uint64_t log_time_ns = 0, publish_time_ns = 0;
  std::vector<std::uint8_t> data;  // kMessage
  std::string metadata_name;       // kMetadata
  std::map<std::string, std::string> metadata;
};

class McapReader {
 public:
  // Throws std::invalid_argument("<path>: ...") for a file that is not MCAP (bad magic) or whose summary
  // CRC does not match.
  explicit McapReader(const std::string& path);
  ~McapReader();
  // The next record in file order (chunks opened in place); false at the end of the data. Throws
  // std::invalid_argument naming the file and byte offset for a CRC mismatch, an unknown compression, a record
  // or chunk that runs past the end of a complete file, or a malformed record.
  bool next(McapRecord& record);
  // Set once the reader stopped early at the end of a file cut short: what it says, else empty.
  const std::string& truncation_warning() const { return warning_; }
  bool has_summary() const { return summary_start_ != 0; }

 private:
  bool next_outer();
  struct State;
  std::unique_ptr<State> s_;
  std::string path_, warning_;
  std::uint64_t size_ = 0, summary_start_ = 0, data_end_ = 0;
  bool complete_ = false;
};

// zstd / lz4 frame; decompress throws std::invalid_argument("<what>: ...") when the data is corrupt or its size
// is not `size`.
std::string mcap_compress(McapCompression compression, const std::string& data);
std::string mcap_decompress(const std::string& compression, const std::uint8_t* data, std::size_t size,
                            std::uint64_t uncompressed_size, const std::string& what);
std::uint32_t crc32(const std::uint8_t* data, std::size_t size, std::uint32_t crc = 0);

}  // namespace stvl::recording::detail

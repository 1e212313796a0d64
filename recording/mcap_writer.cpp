// MCAP writer, compression and CRC (mcap.hpp).
#include <lz4frame.h>
#include <zstd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <set>
#include <stdexcept>

#include "recording/mcap.hpp"

namespace stvl::recording::detail {
namespace {

constexpr char kMagic[] = "\x89MCAP0\r\n";
enum Op : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F
};

// Little-endian record fields.
struct Buf {
  std::string b;
  template <typename T>
  void put(T v) {
    char raw[sizeof(T)];
    std::memcpy(raw, &v, sizeof(T));
    b.append(raw, sizeof(T));
  }
  void str(const std::string& s) { put(static_cast<std::uint32_t>(s.size())), b += s; }
  void map(const std::map<std::string, std::string>& m) {
    Buf inner;
    for (const auto& [k, v] : m) inner.str(k), inner.str(v);
    str(inner.b);
  }
};

std::string record(std::uint8_t op, const std::string& content) {
  Buf r;
  r.put(op);
  r.put(static_cast<std::uint64_t>(content.size()));
  return r.b + content;
}

}  // namespace

std::uint32_t crc32(const std::uint8_t* data, std::size_t size, std::uint32_t crc) {
  static const auto table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  crc = ~crc;
  for (std::size_t i = 0; i < size; ++i) crc = table[(crc ^ data[i]) & 0xFF] ^ (crc >> 8);
  return ~crc;
}

std::string mcap_compress(McapCompression compression, const std::string& data) {
  std::string out;
  if (compression == McapCompression::kZstd) {
    out.resize(ZSTD_compressBound(data.size()));
    const std::size_t n = ZSTD_compress(out.data(), out.size(), data.data(), data.size(), 1);
    if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(n));
    out.resize(n);
  } else if (compression == McapCompression::kLz4) {
    out.resize(LZ4F_compressFrameBound(data.size(), nullptr));
    const std::size_t n = LZ4F_compressFrame(out.data(), out.size(), data.data(), data.size(), nullptr);
    if (LZ4F_isError(n)) throw std::runtime_error(std::string("lz4: ") + LZ4F_getErrorName(n));
    out.resize(n);
  } else {
    out = data;
  }
  return out;
}

std::string mcap_decompress(const std::string& compression, const std::uint8_t* data, std::size_t size,
                            std::uint64_t uncompressed_size, const std::string& what) {
  if (uncompressed_size > (std::uint64_t(1) << 34))
    throw std::invalid_argument(what + ": implausible uncompressed size " + std::to_string(uncompressed_size));
  std::string out(uncompressed_size, '\0');
  if (compression.empty()) {
    if (size != uncompressed_size)
      throw std::invalid_argument(what + ": uncompressed chunk holds " + std::to_string(size) + " bytes, says " +
                                  std::to_string(uncompressed_size));
    if (size) std::memcpy(out.data(), data, size);
  } else if (compression == "zstd") {
    const std::size_t n = ZSTD_decompress(out.data(), out.size(), data, size);
    if (ZSTD_isError(n)) throw std::invalid_argument(what + ": zstd: " + ZSTD_getErrorName(n));
    if (n != uncompressed_size)
      throw std::invalid_argument(what + ": zstd gave " + std::to_string(n) + " bytes, expected " +
                                  std::to_string(uncompressed_size));
  } else if (compression == "lz4") {
    LZ4F_dctx* ctx = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) throw std::runtime_error("lz4: no context");
    std::size_t in_pos = 0, out_pos = 0, status = 1;
    while (status != 0 && in_pos < size) {
      std::size_t out_n = out.size() - out_pos, in_n = size - in_pos;
      status = LZ4F_decompress(ctx, out.data() + out_pos, &out_n, data + in_pos, &in_n, nullptr);
      if (LZ4F_isError(status)) {
        LZ4F_freeDecompressionContext(ctx);
        throw std::invalid_argument(what + ": lz4: " + LZ4F_getErrorName(status));
      }
      in_pos += in_n, out_pos += out_n;
      if (in_n == 0 && out_n == 0) break;
    }
    LZ4F_freeDecompressionContext(ctx);
    if (status != 0 || out_pos != uncompressed_size)
      throw std::invalid_argument(what + ": lz4 frame incomplete or of the wrong size (" + std::to_string(out_pos) +
                                  " of " + std::to_string(uncompressed_size) + " bytes)");
  } else {
    throw std::invalid_argument(what + ": unknown compression '" + compression + "' (expected zstd, lz4 or none)");
  }
  return out;
}

struct McapWriter::State {
  std::FILE* file = nullptr;
  std::string path;
  McapCompression compression;
  std::size_t chunk_bytes;
  std::uint32_t data_crc = 0;
  std::vector<McapSchema> schemas;
  std::vector<McapChannel> channels;
  std::set<std::uint16_t> written;  // channels whose records are in the file
  // The open chunk.
  std::string chunk;
  std::uint64_t chunk_start = ~0ull, chunk_end = 0;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> index;
  // Summary.
  std::vector<std::string> chunk_indexes, metadata_indexes;
  std::map<std::uint16_t, std::uint64_t> counts;
  std::uint64_t start = ~0ull, end = 0;
  std::uint32_t chunk_count = 0, metadata_count = 0;
  bool closed = false;
};

McapWriter::McapWriter(const std::string& path, McapCompression compression, std::string profile, std::string library,
                       std::size_t chunk_bytes)
    : s_(std::make_unique<State>()) {
  s_->path = path, s_->compression = compression, s_->chunk_bytes = chunk_bytes;
  s_->file = std::fopen(path.c_str(), "wb");
  if (!s_->file) throw std::runtime_error("cannot create '" + path + "': " + std::strerror(errno));
  write(std::string(kMagic, 8));
  Buf h;
  h.str(profile), h.str(library);
  write(record(kHeader, h.b));
}

McapWriter::~McapWriter() {
  if (s_->file) std::fclose(s_->file);
}

void McapWriter::write(const std::string& bytes) {
  if (std::fwrite(bytes.data(), 1, bytes.size(), s_->file) != bytes.size())
    throw std::runtime_error("writing '" + s_->path + "' failed: " + std::strerror(errno));
  if (!s_->closed)
    s_->data_crc = crc32(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), s_->data_crc);
  offset_ += bytes.size();
}

std::uint16_t McapWriter::add_schema(const std::string& name, const std::string& encoding, const std::string& data) {
  McapSchema s{static_cast<std::uint16_t>(s_->schemas.size() + 1), name, encoding, data};
  s_->schemas.push_back(s);
  return s.id;
}

std::uint16_t McapWriter::add_channel(std::uint16_t schema_id, const std::string& topic,
                                      const std::string& message_encoding,
                                      const std::map<std::string, std::string>& metadata) {
  McapChannel c{static_cast<std::uint16_t>(s_->channels.size() + 1), schema_id, topic, message_encoding, metadata};
  s_->channels.push_back(c);
  return c.id;
}

namespace {
std::string schema_record(const McapSchema& s) {
  Buf b;
  b.put(s.id), b.str(s.name), b.str(s.encoding), b.str(s.data);
  return record(kSchema, b.b);
}
std::string channel_record(const McapChannel& c) {
  Buf b;
  b.put(c.id), b.put(c.schema_id), b.str(c.topic), b.str(c.message_encoding), b.map(c.metadata);
  return record(kChannel, b.b);
}
}  // namespace

void McapWriter::write_message(std::uint16_t channel_id, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
                               const std::vector<std::uint8_t>& data) {
  if (channel_id == 0 || channel_id > s_->channels.size()) throw std::logic_error("McapWriter: unknown channel");
  if (s_->written.insert(channel_id).second) {
    // Schema and channel go in the chunk of their first message (a schema once per file).
    const McapChannel& c = s_->channels[channel_id - 1];
    bool schema_written = false;
    for (auto id : s_->written)
      if (id != channel_id && s_->channels[id - 1].schema_id == c.schema_id) schema_written = true;
    if (!schema_written && c.schema_id) s_->chunk += schema_record(s_->schemas[c.schema_id - 1]);
    s_->chunk += channel_record(c);
  }
  Buf b;
  b.put(channel_id), b.put(static_cast<std::uint32_t>(s_->counts[channel_id])), b.put(log_time_ns),
      b.put(publish_time_ns);
  s_->index[channel_id].emplace_back(log_time_ns, s_->chunk.size());
  Buf head;
  head.put(std::uint8_t(kMessage)), head.put(static_cast<std::uint64_t>(b.b.size() + data.size()));
  s_->chunk += head.b + b.b;
  s_->chunk.append(reinterpret_cast<const char*>(data.data()), data.size());
  s_->chunk_start = std::min(s_->chunk_start, log_time_ns), s_->chunk_end = std::max(s_->chunk_end, log_time_ns);
  s_->start = std::min(s_->start, log_time_ns), s_->end = std::max(s_->end, log_time_ns);
  ++s_->counts[channel_id];
  ++message_count_;
  if (s_->chunk.size() >= s_->chunk_bytes) flush_chunk();
}

void McapWriter::flush_chunk() {
  if (s_->chunk.empty()) return;
  const auto& raw = s_->chunk;
  const std::string compressed = mcap_compress(s_->compression, raw);
  const std::string name = s_->compression == McapCompression::kZstd  ? "zstd"
                           : s_->compression == McapCompression::kLz4 ? "lz4"
                                                                      : "";
  Buf c;
  c.put(s_->chunk_start == ~0ull ? 0 : s_->chunk_start), c.put(s_->chunk_end),
      c.put(static_cast<std::uint64_t>(raw.size()));
  c.put(crc32(reinterpret_cast<const std::uint8_t*>(raw.data()), raw.size()));
  c.str(name);
  c.put(static_cast<std::uint64_t>(compressed.size()));
  const std::uint64_t chunk_offset = offset_;
  write(record(kChunk, c.b + compressed));
  const std::uint64_t chunk_length = offset_ - chunk_offset;
  std::map<std::string, std::string> unused;
  Buf offsets;
  const std::uint64_t index_start = offset_;
  for (const auto& [channel, entries] : s_->index) {
    Buf m;
    m.put(channel);
    m.put(static_cast<std::uint32_t>(entries.size() * 16));
    for (const auto& [t, o] : entries) m.put(t), m.put(o);
    offsets.put(channel), offsets.put(offset_);
    write(record(kMessageIndex, m.b));
  }
  Buf ci;
  ci.put(s_->chunk_start == ~0ull ? 0 : s_->chunk_start), ci.put(s_->chunk_end), ci.put(chunk_offset),
      ci.put(chunk_length);
  ci.str(offsets.b);  // Map<uint16, uint64> with its byte length
  ci.put(offset_ - index_start);
  ci.str(name);
  ci.put(static_cast<std::uint64_t>(compressed.size())), ci.put(static_cast<std::uint64_t>(raw.size()));
  s_->chunk_indexes.push_back(record(kChunkIndex, ci.b));
  ++s_->chunk_count;
  s_->chunk.clear(), s_->index.clear();
  s_->chunk_start = ~0ull, s_->chunk_end = 0;
}

void McapWriter::write_metadata(const std::string& name, const std::map<std::string, std::string>& values) {
  flush_chunk();
  Buf m;
  m.str(name), m.map(values);
  const std::uint64_t at = offset_;
  write(record(kMetadata, m.b));
  Buf mi;
  mi.put(at), mi.put(offset_ - at), mi.str(name);
  s_->metadata_indexes.push_back(record(kMetadataIndex, mi.b));
  ++s_->metadata_count;
}

void McapWriter::close() {
  if (s_->closed) return;
  flush_chunk();
  Buf de;
  de.put(s_->data_crc);
  s_->closed = true;  // the data CRC is complete
  write(record(kDataEnd, de.b));
  const std::uint64_t summary_start = offset_;
  std::uint32_t crc = 0;
  std::vector<std::tuple<std::uint8_t, std::uint64_t, std::uint64_t>> groups;
  auto group = [&](std::uint8_t op, const std::vector<std::string>& records) {
    if (records.empty()) return;
    const std::uint64_t start = offset_;
    for (const auto& r : records) {
      write(r);
      crc = crc32(reinterpret_cast<const std::uint8_t*>(r.data()), r.size(), crc);
    }
    groups.emplace_back(op, start, offset_ - start);
  };
  std::vector<std::string> schemas, channels;
  for (const auto& s : s_->schemas) schemas.push_back(schema_record(s));
  for (const auto& c : s_->channels)
    if (s_->written.count(c.id)) channels.push_back(channel_record(c));
  Buf st;
  st.put(message_count_), st.put(static_cast<std::uint16_t>(s_->schemas.size())),
      st.put(static_cast<std::uint32_t>(channels.size())), st.put(std::uint32_t(0)), st.put(s_->metadata_count),
      st.put(s_->chunk_count), st.put(s_->start == ~0ull ? 0 : s_->start), st.put(s_->end);
  Buf counts;
  for (const auto& [id, n] : s_->counts) counts.put(id), counts.put(n);
  st.str(counts.b);
  group(kSchema, schemas);
  group(kChannel, channels);
  group(kStatistics, {record(kStatistics, st.b)});
  group(kChunkIndex, s_->chunk_indexes);
  group(kMetadataIndex, s_->metadata_indexes);
  const std::uint64_t offsets_start = offset_;
  std::vector<std::string> offsets;
  for (const auto& [op, start, length] : groups) {
    Buf so;
    so.put(op), so.put(start), so.put(length);
    offsets.push_back(record(kSummaryOffset, so.b));
  }
  for (const auto& r : offsets) {
    write(r);
    crc = crc32(reinterpret_cast<const std::uint8_t*>(r.data()), r.size(), crc);
  }
  Buf footer;
  footer.put(std::uint8_t(kFooter)), footer.put(std::uint64_t(20)), footer.put(summary_start),
      footer.put(offsets_start);
  crc = crc32(reinterpret_cast<const std::uint8_t*>(footer.b.data()), footer.b.size(), crc);
  footer.put(crc);
  write(footer.b + std::string(kMagic, 8));
  if (std::fflush(s_->file) != 0 || std::fclose(s_->file) != 0) {
    s_->file = nullptr;
    throw std::runtime_error("closing '" + s_->path + "' failed: " + std::strerror(errno));
  }
  s_->file = nullptr;
}

}  // namespace stvl::recording::detail

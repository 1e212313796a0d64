// MCAP reader (mcap.hpp): the data section in file order, chunks opened in place.
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "recording/mcap.hpp"

namespace stvl::recording::detail {
namespace {

constexpr char kMagic[] = "\x89MCAP0\r\n";
constexpr std::uint64_t kFooterBytes = 1 + 8 + 20;

// Fields of one record; throws when a field runs past the record.
struct Fields {
  const std::uint8_t* p;
  std::size_t n, at = 0;
  const std::string& what;
  template <typename T>
  T get() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, p + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
  void need(std::uint64_t k) const {
    if (k > n - at) throw std::invalid_argument(what + ": malformed record (a field runs past its end)");
  }
  std::string str() {
    const auto len = get<std::uint32_t>();
    need(len);
    std::string s(reinterpret_cast<const char*>(p + at), len);
    at += len;
    return s;
  }
  std::map<std::string, std::string> map() {
    const auto len = get<std::uint32_t>();
    need(len);
    const std::size_t end = at + len;
    std::map<std::string, std::string> m;
    while (at < end) {
      std::string k = str();
      m[k] = str();
    }
    if (at != end) throw std::invalid_argument(what + ": malformed map");
    return m;
  }
};

}  // namespace

struct McapReader::State {
  std::ifstream in;
  std::uint64_t offset = 8;
  bool done = false;
  // The open chunk.
  std::string chunk;
  std::size_t chunk_at = 0;
  std::uint64_t chunk_offset = 0;
  std::vector<std::uint8_t> record;
  std::uint8_t op = 0;
};

McapReader::McapReader(const std::string& path) : s_(std::make_unique<State>()), path_(path) {
  s_->in.open(path, std::ios::binary);
  if (!s_->in) throw std::invalid_argument(path + ": cannot open");
  s_->in.seekg(0, std::ios::end);
  size_ = static_cast<std::uint64_t>(s_->in.tellg());
  s_->in.seekg(0);
  char magic[8] = {};
  s_->in.read(magic, 8);
  if (!s_->in || std::memcmp(magic, kMagic, 8) != 0)
    throw std::invalid_argument(path + ": not an MCAP file (bad magic: the file must start with \\x89MCAP0\\r\\n)");
  data_end_ = size_;
  if (size_ >= 8 + kFooterBytes + 8) {
    std::string tail(kFooterBytes + 8, '\0');
    s_->in.seekg(static_cast<std::streamoff>(size_ - tail.size()));
    s_->in.read(tail.data(), static_cast<std::streamsize>(tail.size()));
    if (s_->in && std::memcmp(tail.data() + kFooterBytes, kMagic, 8) == 0 && std::uint8_t(tail[0]) == 0x02) {
      complete_ = true;
      const auto* t = reinterpret_cast<const std::uint8_t*>(tail.data());
      std::uint64_t offsets_start = 0;
      std::uint32_t crc = 0;
      std::memcpy(&summary_start_, t + 9, 8);
      std::memcpy(&offsets_start, t + 17, 8);
      std::memcpy(&crc, t + 25, 4);
      const std::uint64_t footer_at = size_ - tail.size();
      data_end_ = footer_at;
      if (summary_start_ > footer_at || offsets_start > footer_at)
        throw std::invalid_argument(path + ": footer points past the end of the file (summary at byte " +
                                    std::to_string(summary_start_) + ")");
      if (summary_start_ != 0) {
        data_end_ = summary_start_;
        if (crc != 0) {
          std::string summary(footer_at - summary_start_, '\0');
          s_->in.seekg(static_cast<std::streamoff>(summary_start_));
          s_->in.read(summary.data(), static_cast<std::streamsize>(summary.size()));
          std::uint32_t c = crc32(reinterpret_cast<const std::uint8_t*>(summary.data()), summary.size());
          c = crc32(t, 25, c);
          if (c != crc)
            throw std::invalid_argument(path + ": summary CRC mismatch (footer says " + std::to_string(crc) +
                                        ", the summary gives " + std::to_string(c) + "): the file is corrupt");
        }
      }
    }
  }
  s_->in.clear();
}

McapReader::~McapReader() = default;

// The next record of the data section into s_->op / s_->record; false at its end.
bool McapReader::next_outer() {
  auto& s = *s_;
  if (s.done) return false;
  const std::string at = path_ + ": record at byte " + std::to_string(s.offset);
  if (s.offset + 9 > data_end_) {
    if (!complete_ && s.offset < size_)
      warning_ = path_ + ": file cut short at byte " + std::to_string(size_) +
                 " (no footer): read up to its last whole record, at byte " + std::to_string(s.offset);
    else if (complete_ && s.offset != data_end_)
      throw std::invalid_argument(at + ": record header runs past the data section");
    s.done = true;
    return false;
  }
  std::uint8_t head[9];
  s.in.seekg(static_cast<std::streamoff>(s.offset));
  s.in.read(reinterpret_cast<char*>(head), 9);
  std::uint64_t length = 0;
  std::memcpy(&length, head + 1, 8);
  if (length > data_end_ - s.offset - 9) {
    if (complete_)
      throw std::invalid_argument(at + ": length " + std::to_string(length) + " runs past the end of the file (" +
                                  std::to_string(size_) + " bytes)");
    warning_ = path_ + ": file cut short at byte " + std::to_string(size_) +
               ": read up to its last whole record, at byte " + std::to_string(s.offset);
    s.done = true;
    return false;
  }
  s.op = head[0];
  s.record.resize(length);
  s.in.read(reinterpret_cast<char*>(s.record.data()), static_cast<std::streamsize>(length));
  if (!s.in) throw std::invalid_argument(at + ": cannot read " + std::to_string(length) + " bytes");
  s.chunk_offset = s.offset;
  s.offset += 9 + length;
  if (s.op == 0x0F || s.op == 0x02) s.done = true;  // data end, or a footer without summary
  return true;
}

namespace {
bool parse(std::uint8_t op, const std::uint8_t* p, std::size_t n, const std::string& what, McapRecord& r) {
  Fields f{p, n, 0, what};
  switch (op) {
    case 0x03:
      r.kind = McapRecord::kSchema;
      r.schema.id = f.get<std::uint16_t>();
      r.schema.name = f.str(), r.schema.encoding = f.str(), r.schema.data = f.str();
      return true;
    case 0x04:
      r.kind = McapRecord::kChannel;
      r.channel.id = f.get<std::uint16_t>();
      r.channel.schema_id = f.get<std::uint16_t>();
      r.channel.topic = f.str(), r.channel.message_encoding = f.str(), r.channel.metadata = f.map();
      return true;
    case 0x05:
      r.kind = McapRecord::kMessage;
      r.channel_id = f.get<std::uint16_t>();
      f.get<std::uint32_t>();
      r.log_time_ns = f.get<std::uint64_t>();
      r.publish_time_ns = f.get<std::uint64_t>();
      r.data.assign(p + f.at, p + n);
      return true;
    case 0x0C:
      r.kind = McapRecord::kMetadata;
      r.metadata_name = f.str(), r.metadata = f.map();
      return true;
    default: return false;  // attachments, indexes and unknown opcodes are skipped
  }
}
}  // namespace

bool McapReader::next(McapRecord& r) {
  auto& s = *s_;
  for (;;) {
    // Records inside the open chunk first.
    if (s.chunk_at < s.chunk.size()) {
      const std::string at =
          path_ + ": chunk at byte " + std::to_string(s.chunk_offset) + ", record at " + std::to_string(s.chunk_at);
      if (s.chunk.size() - s.chunk_at < 9)
        throw std::invalid_argument(at + ": record header runs past the chunk's end");
      const auto* p = reinterpret_cast<const std::uint8_t*>(s.chunk.data()) + s.chunk_at;
      std::uint64_t length = 0;
      std::memcpy(&length, p + 1, 8);
      if (length > s.chunk.size() - s.chunk_at - 9)
        throw std::invalid_argument(at + ": length " + std::to_string(length) + " runs past the chunk's end");
      s.chunk_at += 9 + length;
      if (parse(p[0], p + 9, length, at, r)) return true;
      continue;
    }
    if (!next_outer()) return false;
    const std::string at = path_ + ": record at byte " + std::to_string(s.chunk_offset);
    if (s.op == 0x06) {
      Fields f{s.record.data(), s.record.size(), 0, at};
      f.get<std::uint64_t>(), f.get<std::uint64_t>();
      const auto uncompressed_size = f.get<std::uint64_t>();
      const auto crc = f.get<std::uint32_t>();
      const std::string compression = f.str();
      const auto size = f.get<std::uint64_t>();
      f.need(size);
      s.chunk = mcap_decompress(compression, s.record.data() + f.at, size, uncompressed_size, at + " (chunk)");
      s.chunk_at = 0;
      if (crc != 0) {
        const auto got = crc32(reinterpret_cast<const std::uint8_t*>(s.chunk.data()), s.chunk.size());
        if (got != crc)
          throw std::invalid_argument(at + ": chunk CRC mismatch (recorded " + std::to_string(crc) + ", computed " +
                                      std::to_string(got) + "): the file is corrupt");
      }
      continue;
    }
    if (parse(s.op, s.record.data(), s.record.size(), at, r)) return true;
  }
}

}  // namespace stvl::recording::detail

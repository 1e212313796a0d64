#pragma once
// ROS 2's serialization (not part of the interface): little-endian plain CDR (XCDR1) as rmw_fastrtps writes it.
// A message is a 4-byte encapsulation header (00 01 00 00 = CDR_LE) and its fields in order; each primitive is
// aligned to its size (8 at most) from the end of the header; strings are a uint32 length counting a final NUL,
// then the bytes and the NUL; sequences a uint32 count, then the elements; fixed arrays the elements alone.
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace stvl::recording::detail {

class CdrWriter {
 public:
  explicit CdrWriter(std::vector<std::uint8_t>& out) : out_(out) {
    out_.clear();
    out_.insert(out_.end(), {0x00, 0x01, 0x00, 0x00});
  }
  template <typename T>
  void put(T value) {
    static_assert(std::is_arithmetic_v<T>, "primitives only");
    align(sizeof(T));
    const std::size_t at = out_.size();
    out_.resize(at + sizeof(T));
    std::memcpy(out_.data() + at, &value, sizeof(T));  // x86-64 and aarch64 are little-endian
  }
  void put_string(const std::string& s) {
    put(static_cast<std::uint32_t>(s.size() + 1));
    out_.insert(out_.end(), s.begin(), s.end());
    out_.push_back(0);
  }
  // uint8[] / int8[]: the count, then the bytes.
  void put_bytes(const void* data, std::size_t size) {
    put(static_cast<std::uint32_t>(size));
    const auto* p = static_cast<const std::uint8_t*>(data);
    out_.insert(out_.end(), p, p + size);
  }
  template <typename T>
  void put_array(const T* values, std::size_t n) {  // a fixed-size array: no count
    for (std::size_t i = 0; i < n; ++i) put(values[i]);
  }
  template <typename T>
  void put_sequence(const std::vector<T>& values) {
    put(static_cast<std::uint32_t>(values.size()));
    put_array(values.data(), values.size());
  }

 private:
  void align(std::size_t n) {
    while ((out_.size() - 4) % n) out_.push_back(0);
  }
  std::vector<std::uint8_t>& out_;
};

// Reads what CdrWriter writes (either byte order); throws std::invalid_argument("<what>: ...") when the message
// ends before a field or a length runs past its end.
class CdrReader {
 public:
  CdrReader(const std::uint8_t* data, std::size_t size, std::string what)
      : data_(data), size_(size), what_(std::move(what)) {
    if (size < 4) fail("shorter than the 4-byte CDR header");
    if (data[0] != 0 || data[1] > 1)
      fail("not plain CDR (encapsulation " + std::to_string(data[0]) + "," + std::to_string(data[1]) + ")");
    swap_ = data[1] == 0;  // CDR_BE
    pos_ = 4;
  }
  template <typename T>
  T get() {
    static_assert(std::is_arithmetic_v<T>, "primitives only");
    align(sizeof(T));
    need(sizeof(T));
    std::uint8_t b[sizeof(T)];
    std::memcpy(b, data_ + pos_, sizeof(T));
    if (swap_)
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    T value;
    std::memcpy(&value, b, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }
  std::string get_string() {
    const std::uint32_t n = get<std::uint32_t>();
    need(n);
    std::string s(reinterpret_cast<const char*>(data_ + pos_), n);
    pos_ += n;
    if (!s.empty() && s.back() == '\0') s.pop_back();
    return s;
  }
  // uint8[]: a view into the message (valid while its bytes are).
  std::pair<const std::uint8_t*, std::size_t> get_bytes() {
    const std::uint32_t n = get<std::uint32_t>();
    need(n);
    const std::uint8_t* p = data_ + pos_;
    pos_ += n;
    return {p, n};
  }
  // A sequence's count, checked against the bytes left (each element at least min_element_bytes).
  std::uint32_t get_count(std::size_t min_element_bytes) {
    const std::uint32_t n = get<std::uint32_t>();
    if (min_element_bytes && n > (size_ - pos_) / min_element_bytes)
      fail("a sequence of " + std::to_string(n) + " elements runs past the end");
    return n;
  }
  template <typename T>
  void get_array(T* out, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) out[i] = get<T>();
  }
  [[noreturn]] void fail(const std::string& why) const {
    throw std::invalid_argument(what_ + ": message too short or malformed at byte " + std::to_string(pos_) + ": " +
                                why);
  }

 private:
  void align(std::size_t n) { pos_ = 4 + ((pos_ - 4 + n - 1) / n) * n; }
  void need(std::size_t n) const {
    if (pos_ > size_ || n > size_ - pos_)
      fail("needs " + std::to_string(n) + " more bytes, " + std::to_string(pos_ > size_ ? 0 : size_ - pos_) +
           " left of " + std::to_string(size_));
  }
  const std::uint8_t* data_;
  std::size_t size_, pos_ = 0;
  std::string what_;
  bool swap_ = false;
};

}  // namespace stvl::recording::detail

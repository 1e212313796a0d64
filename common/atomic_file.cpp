#include "common/atomic_file.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace stvl {

void write_file_atomically(const std::filesystem::path& path, const std::string& content) {
  const std::filesystem::path temp = path.string() + ".tmp";
  std::FILE* file = std::fopen(temp.c_str(), "wb");
  if (!file) throw std::runtime_error("cannot write " + path.string() + ": " + std::strerror(errno));
  const bool written = std::fwrite(content.data(), 1, content.size(), file) == content.size();
  const int saved_errno = errno;
  const bool closed = std::fclose(file) == 0;
  if (!written || !closed) {
    std::remove(temp.c_str());
    throw std::runtime_error("cannot write " + path.string() + ": " + std::strerror(written ? errno : saved_errno));
  }
  std::error_code error;
  std::filesystem::rename(temp, path, error);
  if (error) {
    std::remove(temp.c_str());
    throw std::runtime_error("cannot rename " + temp.string() + " to " + path.string() + ": " + error.message());
  }
}

void write_via_temporary(const std::filesystem::path& path,
                         const std::function<void(const std::filesystem::path& temporary)>& write) {
  const std::filesystem::path temp = path.string() + ".tmp";
  try {
    write(temp);
  } catch (...) {
    std::remove(temp.c_str());
    throw;
  }
  std::error_code error;
  std::filesystem::rename(temp, path, error);
  if (error) {
    std::remove(temp.c_str());
    throw std::runtime_error("cannot rename " + temp.string() + " to " + path.string() + ": " + error.message());
  }
}

void ensure_writable_directory(const std::filesystem::path& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw std::runtime_error("cannot create output directory " + dir.string() + ": " + error.message());
  const std::filesystem::path probe = dir / ".stvl-write-test.tmp";
  std::FILE* file = std::fopen(probe.c_str(), "wb");
  if (!file) throw std::runtime_error("output directory " + dir.string() + " is not writable: " + std::strerror(errno));
  std::fclose(file);
  std::remove(probe.c_str());
}

}  // namespace stvl

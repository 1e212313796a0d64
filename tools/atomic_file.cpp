#include "tools/atomic_file.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace stvl::tools {

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

}  // namespace stvl::tools

#pragma once
// Outputs are written to "<path>.tmp" and renamed over <path> once complete, so an interrupted run never
// leaves a file that looks whole. Lives here, the lowest library that writes files; tools/ uses it too.
#include <filesystem>
#include <string>

namespace stvl::mapping {

// Writes `content` to `path` atomically; throws std::runtime_error naming the path when it cannot, and then
// leaves no temporary behind.
void write_file_atomically(const std::filesystem::path& path, const std::string& content);

}  // namespace stvl::mapping

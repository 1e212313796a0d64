#pragma once
// Outputs are written to "<path>.tmp" and renamed over <path> once complete, so an interrupted run never
// leaves a file that looks whole.
#include <filesystem>
#include <string>

namespace stvl::tools {

// Writes `content` to `path` atomically; throws std::runtime_error naming the path when it cannot.
void write_file_atomically(const std::filesystem::path& path, const std::string& content);

// Creates `dir` (and parents) and checks that a file can be written in it; throws std::runtime_error otherwise.
void ensure_writable_directory(const std::filesystem::path& dir);

}  // namespace stvl::tools

#pragma once
// Outputs are written to "<path>.tmp" and renamed over <path> once complete, so an interrupted run never
// leaves a file that looks whole. Every module that writes files uses these.
#include <filesystem>
#include <functional>
#include <string>

namespace stvl {

// Writes `content` to `path` atomically; throws std::runtime_error naming the path when it cannot, and then
// leaves no temporary behind.
void write_file_atomically(const std::filesystem::path& path, const std::string& content);

// For writers that need a file name of their own (OpenVDB, libpng): calls write(temporary path), then renames
// the temporary over `path`. When write throws or the rename fails, the temporary is removed and the error is
// rethrown (a std::runtime_error naming `path` for the rename).
void write_via_temporary(const std::filesystem::path& path,
                         const std::function<void(const std::filesystem::path& temporary)>& write);

// Creates `dir` (and parents) and checks that a file can be written in it; throws std::runtime_error otherwise.
void ensure_writable_directory(const std::filesystem::path& dir);

}  // namespace stvl

#pragma once
// Outputs are written to "<path>.tmp" and renamed over <path> once complete, so an interrupted run never
// leaves a file that looks whole.
#include <filesystem>
#include <string>

#include "mapping/atomic_file.hpp"

namespace stvl::tools {

using mapping::write_file_atomically;

// Creates `dir` (and parents) and checks that a file can be written in it; throws std::runtime_error otherwise.
void ensure_writable_directory(const std::filesystem::path& dir);

}  // namespace stvl::tools

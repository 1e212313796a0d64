#include "common/staged_directory.hpp"

#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <system_error>

#include <fcntl.h>
#include <unistd.h>

namespace stvl {
namespace {

namespace fs = std::filesystem;

// Swaps two existing paths in one step (Linux renameat2 RENAME_EXCHANGE); false where the file system lacks it.
bool exchange(const fs::path& a, const fs::path& b) {
#ifdef RENAME_EXCHANGE
  return ::renameat2(AT_FDCWD, a.c_str(), AT_FDCWD, b.c_str(), RENAME_EXCHANGE) == 0;
#else
  (void)a, (void)b;
  return false;
#endif
}

}  // namespace

StagedDirectory::StagedDirectory(fs::path final_dir) : final_(std::move(final_dir)) {
  if (final_.filename().empty()) final_ = final_.parent_path();  // "out/" names "out"
  staging_ = final_.string() + ".partial-" + std::to_string(::getpid());
  std::error_code error;
  fs::remove_all(staging_, error);  // a staging folder of an earlier process with this id
  error.clear();
  fs::create_directories(staging_, error);
  if (error) throw std::runtime_error("cannot create output directory " + final_.string() + ": " + error.message());
}

StagedDirectory::~StagedDirectory() {
  if (!done_) abandon("the run ended before its outputs were complete");
}

bool folders_apart(const fs::path& a, const fs::path& b) {
  const fs::path x = fs::weakly_canonical(a), y = fs::weakly_canonical(b);
  const auto inside = [](const fs::path& p, const fs::path& folder) {
    const fs::path relative = p.lexically_relative(folder);
    return !relative.empty() && *relative.begin() != "..";
  };
  return !inside(x, y) && !inside(y, x);
}

fs::path StagedDirectory::redirect(const fs::path& p) const {
  const fs::path relative =
      fs::absolute(p).lexically_normal().lexically_relative(fs::absolute(final_).lexically_normal());
  if (relative.empty() || *relative.begin() == ".." || relative == ".") return p;
  return staging_ / relative;
}

void StagedDirectory::commit() {
  std::error_code error;
  if (fs::exists(final_, error)) {
    const fs::path old = final_.string() + ".old-" + std::to_string(::getpid());
    if (!exchange(staging_, final_)) {  // two renames: a moment without the folder, never a mixed one
      fs::remove_all(old, error);
      fs::rename(final_, old, error);
      if (error) throw std::runtime_error("cannot move the old " + final_.string() + " aside: " + error.message());
      fs::rename(staging_, final_, error);
      if (error) {
        std::error_code ignored;
        fs::rename(old, final_, ignored);
        throw std::runtime_error("cannot move " + staging_.string() + " to " + final_.string() + ": " +
                                 error.message());
      }
      fs::remove_all(old, error);
    } else {
      fs::remove_all(staging_, error);  // now the old folder
    }
  } else {
    fs::rename(staging_, final_, error);
    if (error)
      throw std::runtime_error("cannot move " + staging_.string() + " to " + final_.string() + ": " + error.message());
  }
  done_ = true;
}

void StagedDirectory::abandon(const std::string& why) noexcept {
  if (done_) return;
  done_ = true;
  try {
    std::error_code error;
    if (!fs::exists(staging_, error)) return;
    bool wrote = false;  // nothing written (an error before the first output): no folder to mark
    for (const auto& entry : fs::recursive_directory_iterator(staging_, error))
      if (entry.is_regular_file(error)) wrote = true;
    if (!wrote) {
      fs::remove_all(staging_, error);
      return;
    }
    std::ofstream(staging_ / "INCOMPLETE")
        << "This run did not complete; " << final_.string() << " was left as it was.\n"
        << why << "\n";
    const fs::path incomplete = final_.string() + ".incomplete";
    fs::remove_all(incomplete, error);
    fs::rename(staging_, incomplete, error);
  } catch (...) {
  }
}

}  // namespace stvl

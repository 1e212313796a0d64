#pragma once
// An output folder written whole (issue 31): everything goes into a fresh staging folder beside the final one,
// <final>.partial-<pid>, on the same file system; commit() moves it into place in one step (the old folder is
// exchanged with it, then removed), so a reader never sees two runs mixed. A run that fails or is interrupted
// calls abandon(why) (the destructor does when neither was called): the old folder stays untouched and the
// partial output becomes <final>.incomplete, with a file INCOMPLETE saying why.
#include <filesystem>
#include <string>

namespace stvl {

class StagedDirectory {
 public:
  // Creates the staging folder (and the final folder's parents); throws std::runtime_error naming final_dir
  // when it cannot.
  explicit StagedDirectory(std::filesystem::path final_dir);
  ~StagedDirectory();
  StagedDirectory(const StagedDirectory&) = delete;
  StagedDirectory& operator=(const StagedDirectory&) = delete;

  // Where to write now.
  const std::filesystem::path& path() const { return staging_; }
  const std::filesystem::path& final_path() const { return final_; }
  // `p` moved into the staging folder when it lies inside the final folder (a bag written beside the
  // outputs), else `p` unchanged.
  std::filesystem::path redirect(const std::filesystem::path& p) const;

  // Replaces the final folder by the staging folder; throws std::runtime_error naming both when it cannot.
  void commit();
  // Leaves the final folder as it was and renames the staging folder to <final>.incomplete (replacing an
  // earlier one), with INCOMPLETE holding `why`; a staging folder without a file is removed instead. Never throws.
  void abandon(const std::string& why) noexcept;

 private:
  std::filesystem::path final_, staging_;
  bool done_ = false;
};

// Whether output folders a and b can each be staged and committed on their own: neither is the other nor holds it
// (a commit replaces the whole folder, and a folder inside it with it). Compared resolved (weakly_canonical).
bool folders_apart(const std::filesystem::path& a, const std::filesystem::path& b);

}  // namespace stvl

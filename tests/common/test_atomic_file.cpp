#include "common/atomic_file.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/support/command.hpp"

namespace stvl {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class AtomicFile : public ::testing::Test {
 protected:
  std::vector<std::string> names() const { return dir.names(); }
  static std::string read(const fs::path& path) { return test::TempDir::read(path); }
  test::TempDir dir{"atomic_file"};
  const fs::path& dir_ = dir.path();
};

TEST_F(AtomicFile, WritesAndReplacesLeavingNoTemporary) {
  const fs::path file = dir_ / "metrics.json";
  write_file_atomically(file, "first");
  EXPECT_EQ(read(file), "first");
  write_file_atomically(file, std::string("second\0binary", 13));
  EXPECT_EQ(read(file), std::string("second\0binary", 13));
  EXPECT_EQ(names(), std::vector<std::string>{"metrics.json"});
}

TEST_F(AtomicFile, UnwritablePathsThrowNamingThePath) {
  const fs::path missing_dir = dir_ / "no" / "such" / "dir" / "f.txt";
  try {
    write_file_atomically(missing_dir, "x");
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr(missing_dir.string()));
  }
  fs::create_directories(dir_ / "a_directory");
  try {
    write_file_atomically(dir_ / "a_directory", "x");
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr((dir_ / "a_directory").string()));
  }
  EXPECT_TRUE(fs::is_directory(dir_ / "a_directory"));
  EXPECT_EQ(names(), std::vector<std::string>{"a_directory"});  // no .tmp left behind
}

TEST_F(AtomicFile, EnsureWritableDirectoryCreatesParentsAndRejectsFiles) {
  ensure_writable_directory(dir_ / "out" / "frames");
  EXPECT_TRUE(fs::is_directory(dir_ / "out" / "frames"));
  EXPECT_TRUE(fs::is_empty(dir_ / "out" / "frames"));
  write_file_atomically(dir_ / "plain", "x");
  try {
    ensure_writable_directory(dir_ / "plain" / "sub");
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr((dir_ / "plain" / "sub").string()));
  }
}

TEST_F(AtomicFile, WriteViaTemporaryRenamesOnSuccessAndCleansUpOnFailure) {
  const fs::path file = dir_ / "map.vdb";
  write_via_temporary(file, [](const fs::path& temp) {
    EXPECT_EQ(temp.filename().string(), "map.vdb.tmp");
    std::ofstream(temp) << "grid";
  });
  EXPECT_EQ(read(file), "grid");
  EXPECT_THROW(write_via_temporary(file,
                                   [](const fs::path& temp) {
                                     std::ofstream(temp) << "half";
                                     throw std::runtime_error("writer failed");
                                   }),
               std::runtime_error);
  EXPECT_EQ(read(file), "grid");  // the old file stays whole
  EXPECT_EQ(names(), std::vector<std::string>{"map.vdb"});
}

}  // namespace
}  // namespace stvl

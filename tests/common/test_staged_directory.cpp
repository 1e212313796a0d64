#include "common/staged_directory.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

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

class StagedDirectoryTest : public ::testing::Test {
 protected:
  static void put(const fs::path& file, const std::string& text) {
    fs::create_directories(file.parent_path());
    std::ofstream(file) << text;
  }
  static std::string read(const fs::path& path) { return test::TempDir::read(path); }
  test::TempDir dir{"staged_directory"};
  const fs::path out = dir.path() / "out";
};

// A second run into the same folder must not keep the first one's files (issue 31: stale frames/*.png).
TEST_F(StagedDirectoryTest, CommitReplacesTheOldFolderWhole) {
  put(out / "frames" / "depth_00007_color.png", "old run");
  put(out / "metrics.json", "old");
  {
    StagedDirectory staged(out);
    EXPECT_NE(staged.path(), out);
    put(staged.path() / "metrics.json", "new");
    put(staged.path() / "frames" / "depth_00001_color.png", "new run");
    EXPECT_EQ(read(out / "metrics.json"), "old");  // untouched until the run completes
    staged.commit();
  }
  EXPECT_EQ(read(out / "metrics.json"), "new");
  EXPECT_TRUE(fs::exists(out / "frames" / "depth_00001_color.png"));
  EXPECT_FALSE(fs::exists(out / "frames" / "depth_00007_color.png"));
  EXPECT_EQ(dir.names(), std::vector<std::string>{"out"});  // no staging or old folder left
}

TEST_F(StagedDirectoryTest, CommitIntoANewFolder) {
  StagedDirectory staged(dir.path() / "a" / "b" / "out");
  put(staged.path() / "junit.xml", "x");
  staged.commit();
  EXPECT_EQ(read(dir.path() / "a" / "b" / "out" / "junit.xml"), "x");
}

// A run that fails or is interrupted leaves the old results as they were and its own output marked.
TEST_F(StagedDirectoryTest, AbandonKeepsTheOldFolderAndMarksThePartialOne) {
  put(out / "metrics.json", "old");
  {
    StagedDirectory staged(out);
    put(staged.path() / "map.vdb", "partial");
    staged.abandon("interrupted by signal 2 after 40 frames");
  }
  EXPECT_EQ(read(out / "metrics.json"), "old");
  EXPECT_THAT(read(dir.path() / "out.incomplete" / "INCOMPLETE"), HasSubstr("interrupted by signal 2 after 40 frames"));
  EXPECT_TRUE(fs::exists(dir.path() / "out.incomplete" / "map.vdb"));
  {
    StagedDirectory staged(out);  // an exception: the destructor abandons, replacing the earlier .incomplete
    put(staged.path() / "frames" / "x.png", "partial 2");
  }
  EXPECT_FALSE(fs::exists(dir.path() / "out.incomplete" / "map.vdb"));
  EXPECT_TRUE(fs::exists(dir.path() / "out.incomplete" / "frames" / "x.png"));
  EXPECT_EQ(read(out / "metrics.json"), "old");
}

TEST_F(StagedDirectoryTest, RedirectsPathsInsideTheFinalFolder) {
  StagedDirectory staged(out);
  EXPECT_EQ(staged.redirect(out / "run.bag"), staged.path() / "run.bag");
  EXPECT_EQ(staged.redirect(dir.path() / "elsewhere.bag"), dir.path() / "elsewhere.bag");
  staged.commit();
}

TEST_F(StagedDirectoryTest, FoldersApartWhenNeitherHoldsTheOther) {
  EXPECT_TRUE(folders_apart(out, dir.path() / "twin"));
  EXPECT_TRUE(folders_apart(out, dir.path() / "out_twin"));  // a name that starts alike is another folder
  EXPECT_FALSE(folders_apart(out, out));
  EXPECT_FALSE(folders_apart(out, out / "twin"));
  EXPECT_FALSE(folders_apart(out / "twin", out));
  EXPECT_FALSE(folders_apart(out, out / ".." / "out"));  // the same folder, written another way
}

TEST_F(StagedDirectoryTest, AFolderUnderAFileThrowsNamingIt) {
  put(dir.path() / "plain_file", "");
  try {
    StagedDirectory staged(dir.path() / "plain_file" / "out");
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("plain_file/out"));
  }
}

}  // namespace
}  // namespace stvl

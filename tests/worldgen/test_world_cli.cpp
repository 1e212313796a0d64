// stvl-bench world from-map / world generate: the files it writes, determinism through the command line, and bad
// input: exit 2 naming the file and the fix, with nothing complete-looking left in the output folder.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/support/command.hpp"
#include "tests/worldgen/helpers.hpp"

namespace stvl::worldgen {
namespace {

namespace fs = std::filesystem;
using stvl::test::quoted;
using ::testing::HasSubstr;

const std::string kOfficeFloor = std::string(STVL_SOURCE_DIR) + "/worlds/maps/office_floor.yaml";

class WorldCli : public ::testing::Test {
 protected:
  void SetUp() override {
    binary_ = stvl::test::stvl_bench_binary();
    if (binary_.empty()) GTEST_SKIP() << "stvl-bench not built (build the stvl-bench target)";
  }
  stvl::test::Outcome run(const std::string& args) const {
    return stvl::test::run_shell("timeout 120 " + quoted(binary_.string()) + " world " + args);
  }
  std::string out(const std::string& name) const { return (dir_.path() / name).string(); }
  static std::string read(const std::string& path) { return stvl::test::TempDir::read(path); }

  fs::path binary_;
  test::TempDir dir_;
};

TEST_F(WorldCli, GenerateWritesTheSameFilesForTheSameSeed) {
  ASSERT_EQ(run("generate --seed 5 --out " + quoted(out("a"))).exit_code, 0);
  const auto again = run("generate --seed 5 --out " + quoted(out("b")));
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_THAT(again.output, HasSubstr("office seed 5: 20.0 x 12.0 m"));
  for (const char* file : {"world.xml", "scenario.yaml", "robot.xml"})
    EXPECT_EQ(read(out("a") + "/" + file), read(out("b") + "/" + file)) << file;
  ASSERT_EQ(run("generate --seed 6 --out " + quoted(out("c"))).exit_code, 0);
  EXPECT_NE(read(out("a") + "/world.xml"), read(out("c") + "/world.xml"));
  EXPECT_EQ(read(out("a") + "/robot.xml"), read(std::string(STVL_SOURCE_DIR) + "/worlds/robot.xml"));
}

TEST_F(WorldCli, FromMapWritesWorldRobotAndScenarioAndReplacesTheFolderWhole) {
  fs::create_directories(out("m"));
  dir_.write("m/stale.txt", "from an earlier run");
  const auto r =
      run("from-map " + quoted(kOfficeFloor) + " --out " + quoted(out("m")) + " --start=-0.3,1.0 --goal 7.5,-1.0");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::is_regular_file(out("m") + "/world.xml"));
  EXPECT_TRUE(fs::is_regular_file(out("m") + "/robot.xml"));
  EXPECT_FALSE(fs::exists(out("m") + "/stale.txt"));
  const std::string yaml = read(out("m") + "/scenario.yaml");
  EXPECT_THAT(yaml, HasSubstr("name: office_floor\n"));
  EXPECT_THAT(yaml, HasSubstr("start: [-0.300, 1.000, "));
  EXPECT_THAT(yaml, HasSubstr(", [7.500, -1.000]]\n"));
}

TEST_F(WorldCli, BadMapsAndPointsExitTwoAndLeaveNothingBehind) {
  const std::string m = dir_.write("bad.yaml", test::map_yaml("bad.pgm", 0.05));
  dir_.write("bad.pgm", "P5\n4 4\n255\nab");  // truncated
  const struct {
    std::string args, message;
  } cases[] = {
      {"from-map " + quoted(m), "bad.pgm: the PGM ends after 2 of its 16 pixels (truncated)"},
      {"from-map " + quoted(dir_.write("nan.yaml", test::map_yaml("bad.pgm", 0.05, "[.nan, 0, 0]"))),
       "nan.yaml:3: origin: x and y must be finite"},
      {"from-map " + quoted(dir_.write("zero.yaml", test::map_yaml("bad.pgm", 0.0))),
       "zero.yaml:2: resolution: must be a finite number"},
      {"from-map " + quoted(dir_.write("key.yaml", test::map_yaml("bad.pgm") + "orign: [0, 0, 0]\n")),
       "did you mean 'origin'?"},
      {"from-map " + quoted(dir_.write("gone.yaml", test::map_yaml("gone.pgm"))), "image: cannot read"},
      {"from-map " + quoted(kOfficeFloor) + " --start 2.0,0.15", "--start (2.000, 0.150) m: inside a wall"},
      {"from-map " + quoted(kOfficeFloor) + " --goal 50,50", "--goal (50.000, 50.000) m: outside the map"},
      {"from-map " + quoted(kOfficeFloor) + " --goal 8.5,3.5", "--goal (8.500, 3.500) m: in unknown space"},
      {"from-map " + quoted(kOfficeFloor) + " --start 1,x", "--start '1,x': expected two numbers"},
      {"generate --size 5x5", "the building must be 12..60 m by 8..40 m"},
      {"generate --people 30", "--people 30: must lie in 0..20"},
  };
  for (const auto& c : cases) {
    const auto r = run(c.args + " --out " + quoted(out("bad_out")));
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.output;
    EXPECT_THAT(r.output, HasSubstr(c.message)) << c.args;
    EXPECT_FALSE(fs::exists(out("bad_out"))) << c.args;
  }
}

}  // namespace
}  // namespace stvl::worldgen

// Runs the stvl-bench executable (built next to this test binary) and checks exit codes and messages for bad
// input. Every case must fail before simulating; `timeout` bounds a case that would wrongly start a run.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "tests/support/command.hpp"

namespace stvl::tools {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

constexpr int kBadInput = 2;
const std::string kDefaultScenario = std::string(STVL_SOURCE_DIR) + "/scenarios/office_corridor.yaml";

using test::Outcome;
using test::quoted;

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    binary_ = test::stvl_bench_binary();
    if (binary_.empty()) GTEST_SKIP() << "stvl-bench not built (build the stvl-bench target)";
    dir_ = fs::temp_directory_path() / ("stvl_tools_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }

  // Runs stvl-bench with `args` (already quoted where needed) from the temporary folder.
  Outcome run(const std::string& args) const {
    return test::run_shell("cd " + quoted(dir_.string()) + " && timeout 60 " + quoted(binary_.string()) + " " + args);
  }

  std::string write(const std::string& name, const std::string& text) const {
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    return path.string();
  }

  std::string scenario_for_world(const std::string& world) const {
    return "name: tools\nworld: " + world + "\nrobot:\n  waypoints: [[0, 0], [1, 0]]\n  speed_mps: 0.5\n";
  }

  std::string out_arg() const { return "--out " + quoted((dir_ / "out").string()); }

  fs::path binary_;
  fs::path dir_;
};

TEST_F(Cli, HelpExitsZero) {
  const Outcome help = run("--help");
  EXPECT_EQ(help.exit_code, 0) << help.output;
  EXPECT_THAT(help.output, HasSubstr("run"));
  const Outcome run_help = run("run --help");
  EXPECT_EQ(run_help.exit_code, 0) << run_help.output;
  EXPECT_THAT(run_help.output, HasSubstr("--voxel-size"));
}

TEST_F(Cli, UnknownSubcommandsAndOptionsExitTwo) {
  EXPECT_EQ(run("").exit_code, kBadInput);
  EXPECT_EQ(run("frobnicate").exit_code, kBadInput);
  EXPECT_EQ(run("--frobnicate").exit_code, kBadInput);
  const Outcome option = run("run " + quoted(kDefaultScenario) + " --frobnicate " + out_arg());
  EXPECT_EQ(option.exit_code, kBadInput) << option.output;
  EXPECT_THAT(option.output, HasSubstr("--frobnicate"));
  EXPECT_EQ(run("run " + quoted(kDefaultScenario) + " --bag-compression zip " + out_arg()).exit_code, kBadInput);
  EXPECT_EQ(run("run " + quoted(kDefaultScenario) + " --voxel-size big " + out_arg()).exit_code, kBadInput);
  const Outcome seed = run("run " + quoted(kDefaultScenario) + " --seed -1 " + out_arg());
  EXPECT_EQ(seed.exit_code, kBadInput) << seed.output;
  EXPECT_THAT(seed.output, HasSubstr("--seed"));
  const Outcome huge = run("run " + quoted(kDefaultScenario) + " --seed 99999999999999999999 " + out_arg());
  EXPECT_EQ(huge.exit_code, kBadInput) << huge.output;
  EXPECT_THAT(huge.output, HasSubstr("exceeds the largest seed"));
  const Outcome word = run("run " + quoted(kDefaultScenario) + " --seed 12ab " + out_arg());
  EXPECT_EQ(word.exit_code, kBadInput) << word.output;
  EXPECT_THAT(word.output, HasSubstr("expected a non-negative integer"));
}

TEST_F(Cli, MissingScenarioFileExitsTwoNamingIt) {
  const std::string missing = (dir_ / "no_such_scenario.yaml").string();
  const Outcome o = run("run " + quoted(missing) + " " + out_arg());
  EXPECT_EQ(o.exit_code, kBadInput) << o.output;
  EXPECT_THAT(o.output, HasSubstr(missing));
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

TEST_F(Cli, UnknownKeyExitsTwoNamingFileLineAndKey) {
  const std::string file = write("typo.yaml", scenario_for_world("w.xml") + "map:\n  voxel_sze: 0.1\n");
  const Outcome o = run("run " + quoted(file) + " " + out_arg());
  EXPECT_EQ(o.exit_code, kBadInput) << o.output;
  EXPECT_THAT(o.output, HasSubstr(file + ":7: map.voxel_sze: unknown key"));
}

TEST_F(Cli, SyntaxErrorExitsTwoNamingTheLine) {
  const std::string file = write("syntax.yaml", "name: a\nworld: b\n  robot: 1\n");
  const Outcome o = run("run " + quoted(file) + " " + out_arg());
  EXPECT_EQ(o.exit_code, kBadInput) << o.output;
  EXPECT_THAT(o.output, HasSubstr(file + ":3: YAML syntax error"));
}

TEST_F(Cli, MissingWorldExitsTwoNamingTheWorldPath) {
  const std::string file = write("no_world.yaml", scenario_for_world("worlds/missing.xml"));
  const Outcome o = run("run " + quoted(file) + " " + out_arg());
  EXPECT_EQ(o.exit_code, kBadInput) << o.output;
  EXPECT_THAT(o.output, HasSubstr((dir_ / "worlds" / "missing.xml").string()));
}

TEST_F(Cli, MalformedWorldExitsTwoWithMujocosMessage) {
  write("broken.xml", "<mujoco>\n  <worldbody>\n    <geom type=\"box\" size=\"1 1 1\">\n  </worldbody>\n</mujoco>\n");
  const std::string file = write("broken_world.yaml", scenario_for_world("broken.xml"));
  const Outcome o = run("run " + quoted(file) + " " + out_arg());
  EXPECT_EQ(o.exit_code, kBadInput) << o.output;
  EXPECT_THAT(o.output, HasSubstr("cannot load world '" + (dir_ / "broken.xml").string() + "'"));
  EXPECT_THAT(o.output, HasSubstr("XML_ERROR_MISMATCHED_ELEMENT"));
}

TEST_F(Cli, WaypointsOutsideTheWorldExitTwoBeforeDriving) {
  const std::string world = std::string(STVL_SOURCE_DIR) + "/worlds/office_corridor.xml";
  for (const char* waypoints : {"[[0, 0], [1e308, 0]]", "[[0, 0], [5, 0], [5, 40]]"}) {
    SCOPED_TRACE(waypoints);
    const std::string file = write(
        "far.yaml", "name: far\nworld: " + world + "\nrobot:\n  waypoints: " + waypoints + "\n  speed_mps: 0.5\n");
    const Outcome o = run("run " + quoted(file) + " " + out_arg());
    EXPECT_EQ(o.exit_code, kBadInput) << o.output;
    EXPECT_THAT(o.output, HasSubstr("lies outside the world's extent"));
    EXPECT_THAT(o.output, HasSubstr("robot.waypoints["));
  }
  const std::string start = write("start.yaml", "name: far\nworld: " + world +
                                                    "\nrobot:\n  start: [-50, 0, 0]\n  waypoints: [[0, 0], [1, 0]]\n"
                                                    "  speed_mps: 0.5\n");
  const Outcome o = run("run " + quoted(start) + " " + out_arg());
  EXPECT_EQ(o.exit_code, kBadInput) << o.output;
  EXPECT_THAT(o.output, HasSubstr("robot.start (-50, 0) m lies outside"));
}

TEST_F(Cli, BadOverridesExitTwo) {
  const std::string scenario = quoted(kDefaultScenario);
  for (const char* bad : {"--voxel-size 0", "--voxel-size nan", "--voxel-size -0.05", "--duration 0", "--filter median",
                          "--device tpu", "--gl glx", "--noise maybe"}) {
    SCOPED_TRACE(bad);
    const Outcome o = run("run " + scenario + " " + bad + " " + out_arg());
    EXPECT_EQ(o.exit_code, kBadInput) << o.output;
    EXPECT_THAT(o.output, HasSubstr("error"));
  }
  const Outcome voxel = run("run " + scenario + " --voxel-size 0 " + out_arg());
  EXPECT_THAT(voxel.output, HasSubstr("--voxel-size"));
  EXPECT_THAT(voxel.output, HasSubstr("voxel_size"));
}

TEST_F(Cli, UnwritableOutExitsTwoNamingIt) {
  write("plain_file", "x");
  const std::string out = (dir_ / "plain_file" / "out").string();
  const Outcome o = run("run " + quoted(kDefaultScenario) + " --out " + quoted(out));
  EXPECT_EQ(o.exit_code, kBadInput) << o.output;
  EXPECT_THAT(o.output, HasSubstr(out));
}

// replay --list-topics on rosbag2's own split recording and librealsense's D435 bag (../shared/realdata beside the
// checkout): every topic with its type and count and what the replay reads; exit 0 even without a depth topic.
TEST_F(Cli, ReplayListTopicsSaysWhatARecordingHoldsAndWhatIsRead) {
  const fs::path realdata = fs::path(STVL_SOURCE_DIR) / ".." / "shared" / "realdata";
  if (!fs::exists(realdata / "rosbag2" / "split_mcap")) GTEST_SKIP() << realdata << " is absent";
  const Outcome split = run("replay " + quoted((realdata / "rosbag2" / "split_mcap").string()) + " --list-topics");
  EXPECT_EQ(split.exit_code, 0) << split.output;
  EXPECT_THAT(split.output, HasSubstr("rosbag2 (mcap), 5 file(s), 8 topic(s)"));
  EXPECT_THAT(split.output, HasSubstr("  AAA  std_msgs/msg/String  804 message(s)  cdr/ros2msg  not read\n"));
  EXPECT_THAT(split.output, HasSubstr("replay would stop: "));
  EXPECT_THAT(split.output, HasSubstr("no depth topic"));
  const Outcome d435 =
      run("replay " + quoted((realdata / "d435_office_corner" / "single_depth_color_640x480.bag").string()) +
          " --list-topics");
  EXPECT_EQ(d435.exit_code, 0) << d435.output;
  EXPECT_THAT(d435.output, HasSubstr("/device_0/sensor_0/Depth_0/image/data  sensor_msgs/Image  2 message(s)  "
                                     "ros1/ros1msg  read as depth"));
  EXPECT_THAT(d435.output, HasSubstr("replay reads 2 depth frames from /device_0/sensor_0/Depth_0/image/data"));
  EXPECT_FALSE(fs::exists(dir_ / "out"));  // nothing replayed, nothing written
  const Outcome missing = run("replay " + quoted((dir_ / "nothing.mcap").string()) + " --list-topics");
  EXPECT_EQ(missing.exit_code, kBadInput) << missing.output;
  EXPECT_THAT(missing.output, HasSubstr("nothing.mcap: no such file"));
}

}  // namespace
}  // namespace stvl::tools

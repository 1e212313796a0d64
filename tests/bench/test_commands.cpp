// Runs each benchmark subcommand of the stvl-bench executable (built next to this test binary) once, with the
// shortest settings, and checks bad options exit with code 2 before measuring anything.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/support/command.hpp"

namespace stvl::bench {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using test::Outcome;

class BenchCommands : public ::testing::Test {
 protected:
  void SetUp() override {
    binary_ = test::stvl_bench_binary();
    if (binary_.empty()) GTEST_SKIP() << "stvl-bench not built (build the stvl-bench target)";
  }
  Outcome run(const std::string& args) const {
    return test::run_shell("timeout 120 " + test::quoted(binary_.string()) + " " + args);
  }

  fs::path binary_;
};

TEST_F(BenchCommands, EachBenchmarkRunsOnce) {
  const Outcome filter = run("filter-bench --clouds 1 --voxel 0.1 --warmup 0 --reps 1 --threads 1 --no-cuda");
  EXPECT_EQ(filter.exit_code, 0) << filter.output;
  EXPECT_THAT(filter.output, HasSubstr("| corridor_t02.0 | csnb/cpu | 0.100 |"));
  const Outcome map = run("map-bench --frames 2 --sizes 100 --threads 1 --no-octomap");
  EXPECT_EQ(map.exit_code, 0) << map.output;
  EXPECT_THAT(map.output, HasSubstr("| 100 |"));
  const Outcome sensors = run("sensors-bench --frames 2 --gl osmesa");
  EXPECT_EQ(sensors.exit_code, 0) << sensors.output;
  EXPECT_THAT(sensors.output, HasSubstr("osmesa   640x480"));
  const Outcome sim = run("sim-bench --duration 0.2");
  EXPECT_EQ(sim.exit_code, 0) << sim.output;
  EXPECT_THAT(sim.output, HasSubstr("steps/s"));
}

TEST_F(BenchCommands, BadOptionsExitWithCode2) {
  for (const char* args :
       {"filter-bench --peer octomap", "filter-bench --clouds 0", "map-bench --frames 0", "sensors-bench --gl vulkan",
        "sensors-bench --frames 0", "sim-bench --duration -1", "sim-bench --world /nonexistent.xml"}) {
    const Outcome outcome = run(args);
    EXPECT_EQ(outcome.exit_code, 2) << args << "\n" << outcome.output;
  }
}

}  // namespace
}  // namespace stvl::bench

// Sweeps over many worlds: the world axis (prepare_worlds with a stand-in for `stvl-bench world`, the grid, the
// point commands) and the figures' distribution and the checks' shares over the worlds (over_worlds).
#include "analysis/sweep.hpp"
#include "analysis/sweep_worlds.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "tests/support/command.hpp"
#include "tests/support/invalid_argument.hpp"

namespace stvl::analysis {
namespace {

namespace fs = std::filesystem;
using test::invalid_argument_of;
using ::testing::HasSubstr;

// A stand-in for stvl-bench: `world generate --seed N --out DIR` and `world from-map F --out DIR` write
// DIR/scenario.yaml naming what they were given; seed 13 fails the way a bad world would.
std::string fake_binary(const fs::path& dir) {
  const fs::path path = dir / "fake-stvl-bench";
  std::ofstream(path) << "#!/bin/sh\n"
                         "for a in \"$@\"; do last=\"$a\"; done\n"
                         "case \"$*\" in *'--seed 13 '*) echo 'no path fits seed 13' >&2; exit 2;; esac\n"
                         "mkdir -p \"$last\" && echo \"# $*\" > \"$last/scenario.yaml\"\n";
  fs::permissions(path, fs::perms::owner_all);
  return path.string();
}

TEST(SweepWorlds, GeneratedMapsAndScenarioFilesBecomeWorlds) {
  const test::TempDir dir("sweep_worlds");
  const std::string bin = fake_binary(dir.path());
  const auto generated = prepare_worlds(bin, "generate:3..4", (dir.path() / "out").string());
  ASSERT_EQ(generated.size(), 2u);
  EXPECT_EQ(generated[0].label, "generate:3");
  EXPECT_EQ(generated[0].scenario, (dir.path() / "out" / "worlds" / "generate_3" / "scenario.yaml").string());
  EXPECT_THAT(test::TempDir::read(generated[1].scenario), HasSubstr("world generate --seed 4 --out"));
  EXPECT_THAT(generated[1].make_command, HasSubstr("'world' 'generate' '--seed' '4'"));

  std::ofstream(dir.path() / "floor.yaml") << "image: floor.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n";
  std::ofstream(dir.path() / "mine.yaml") << "name: mine\nworld: ../worlds/office_corridor.xml\n";
  const auto listed =
      prepare_worlds(bin, (dir.path() / "floor.yaml").string() + "," + (dir.path() / "mine.yaml").string(),
                     (dir.path() / "out").string());
  ASSERT_EQ(listed.size(), 2u);
  // A scenario is run as it is; a map is made into a world first (so it comes after the scenario files).
  EXPECT_EQ(listed[0].label, "mine.yaml");
  EXPECT_EQ(listed[0].scenario, (dir.path() / "mine.yaml").string());
  EXPECT_TRUE(listed[0].make_command.empty());
  EXPECT_EQ(listed[1].label, "map:floor");
  EXPECT_THAT(test::TempDir::read(listed[1].scenario), HasSubstr("world from-map"));
}

TEST(SweepWorlds, BadWorldsNameTheEntry) {
  const test::TempDir dir("sweep_worlds_bad");
  const std::string bin = fake_binary(dir.path());
  const std::string out = (dir.path() / "out").string();
  EXPECT_THAT(invalid_argument_of([&] { prepare_worlds(bin, "generate:12..13", out); }),
              HasSubstr("--worlds generate:13: `"));
  EXPECT_THAT(invalid_argument_of([&] { prepare_worlds(bin, "generate:12..13", out); }),
              HasSubstr("no path fits seed 13"));
  EXPECT_THAT(invalid_argument_of([&] { prepare_worlds(bin, "generate:x", out); }), HasSubstr("--seeds x"));
  EXPECT_THAT(invalid_argument_of([&] { prepare_worlds(bin, "nowhere.yaml", out); }),
              HasSubstr("--worlds nowhere.yaml: no such file"));
}

TEST(SweepWorlds, WorldsVarySlowestAndEachPointRunsItsWorldsScenario) {
  const std::vector<SweepWorld> worlds = {{"generate:1", "/w/1/scenario.yaml", "make 1"},
                                          {"generate:2", "/w/2/scenario.yaml", "make 2"}};
  const auto points = sweep_grid({parse_sweep_axis("map.clearing_mode=frustum,raycast")}, {}, 100, worlds);
  ASSERT_EQ(points.size(), 4u);
  EXPECT_EQ(points[0].name, "000_generate-1_map.clearing_mode=frustum");
  EXPECT_EQ(points[1].world, "generate:1");
  EXPECT_EQ(points[2].world, "generate:2");
  EXPECT_EQ(points[3].make_world, "make 2");
  const auto argv = point_command("bin", "unused.yaml", "/out", points[3]);
  EXPECT_EQ(argv[2], "/w/2/scenario.yaml");
  EXPECT_THROW(sweep_grid({}, {}, 1, worlds), std::invalid_argument);  // 2 worlds > 1 point allowed
  EXPECT_EQ(sweep_grid({}, {}, 100, worlds).size(), 2u);               // worlds alone make a grid
}

nlohmann::json row(const std::string& world, double f1, int phantoms, const std::string& drive, bool missing = false) {
  nlohmann::json r = {{"point", world},
                      {"world", world},
                      {"sets", {{"map.clearing_mode", "frustum"}}},
                      {"make_world", "make " + world},
                      {"command", "run " + world},
                      {"state", missing ? "missing" : "passed"}};
  if (!missing) {
    r["figures"] = {{"f1", f1}, {"final_phantoms", phantoms}};
    r["checks"] = {{"drive", drive}, {"phantoms", phantoms == 0 ? "pass" : "fail"}};
  }
  return r;
}

TEST(SweepWorlds, DistributionsWorstWorldsAndShares) {
  nlohmann::json table = {{"axes", {"map.clearing_mode"}}, {"rows", nlohmann::json::array()}};
  table["rows"].push_back(row("generate:1", 0.90, 0, "pass"));
  table["rows"].push_back(row("generate:2", 0.80, 2, "pass"));
  table["rows"].push_back(row("generate:3", 0.95, 0, "skip"));
  table["rows"].push_back(row("generate:4", 0.70, 1, "fail"));
  table["rows"].push_back(row("generate:5", 0.0, 0, "", true));  // did not run
  const nlohmann::json summary = over_worlds(table);
  ASSERT_EQ(summary["groups"].size(), 1u);
  const auto& g = summary["groups"][0];
  EXPECT_EQ(g["group"], "map.clearing_mode=frustum");
  EXPECT_EQ(g["worlds"], 5);
  const auto& f1 = g["figures"]["f1"];
  EXPECT_EQ(f1["n"], 4);
  EXPECT_DOUBLE_EQ(f1["mean"].get<double>(), (0.90 + 0.80 + 0.95 + 0.70) / 4);
  EXPECT_DOUBLE_EQ(f1["p5"].get<double>(), 0.70);     // nearest rank: ceil(0.05 * 4) = 1st
  EXPECT_DOUBLE_EQ(f1["p95"].get<double>(), 0.95);    // ceil(0.95 * 4) = 4th
  EXPECT_DOUBLE_EQ(f1["worst"].get<double>(), 0.70);  // lowest score
  EXPECT_EQ(f1["worst_world"], "generate:4");
  EXPECT_EQ(f1["reproduce"], "make generate:4 && run generate:4");
  EXPECT_EQ(g["figures"]["final_phantoms"]["worst"], 2);  // most phantoms
  EXPECT_EQ(g["figures"]["final_phantoms"]["worst_world"], "generate:2");
  // drive: 2 pass, 1 fail, 1 skipped (not counted), the missing world fails.
  EXPECT_EQ(g["checks"]["drive"]["held"], 2);
  EXPECT_EQ(g["checks"]["drive"]["evaluated"], 4);
  EXPECT_DOUBLE_EQ(g["checks"]["drive"]["share"].get<double>(), 0.5);
  EXPECT_EQ(g["checks"]["drive"]["first_failing_world"], "generate:4");
  EXPECT_EQ(g["checks"]["phantoms"]["held"], 2);
  EXPECT_EQ(g["checks"]["phantoms"]["evaluated"], 5);
  EXPECT_THAT(over_worlds_html(summary), HasSubstr("Over 5 worlds: map.clearing_mode=frustum"));
}

}  // namespace
}  // namespace stvl::analysis

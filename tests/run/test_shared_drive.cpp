// Twins (run/shared_drive.hpp, run_twins in run/runner.hpp): on the fixture's robot between two walls with a noisy
// camera, each twin's result is what run_scenario gives for its scenario alone; and the sets a twin may have.
#include "run/shared_drive.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "run/runner.hpp"
#include "tests/support/fixture.hpp"
#include "tests/support/invalid_argument.hpp"

namespace stvl::run {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

std::string file_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class SharedDriveTest : public test::MujocoTest {
 protected:
  // The robot drives towards the wall at an angle; a small noisy camera at 10 Hz; 0.1 m voxels.
  config::Scenario scenario(const std::vector<std::string>& sets) const {
    const fs::path file = fs::path(world_.path()).parent_path() / "twins.yaml";
    std::ofstream(file) << "name: twins\nworld: " << world_.path() << "\nduration_s: 2.0\n"
                        << "robot:\n  waypoints: [[0, 0], [1.2, 0.4]]\n  speed_mps: 0.5\n"
                        << "camera:\n  preset: custom\n  intrinsics: {width: 96, height: 72, fx: 80.0, fy: 80.0, "
                           "cx: 47.5, cy: 35.5}\n  min_range_m: 0.2\n  max_range_m: 6.0\n  rate_hz: 10\n"
                        << "  noise: {enabled: true}\n"
                        << "filter:\n  type: voxel\n  device: cpu\n  voxel: {voxel_size_m: 0.1}\n"
                        << "map:\n  voxel_size: 0.1\n"
                        << "evaluation:\n  evaluate_every_s: 0.5\n  recall_window_s: 0.5\n";
    return config::load_scenario(file.string(), sets);
  }
  RunOptions options(const std::string& name) const {
    RunOptions o;
    o.out_dir = (fs::path(world_.path()).parent_path() / name).string();
    o.progress = false;
    return o;
  }
  // The same run, alone and as a twin: the same frames, series, figures, checks and map files.
  void expect_same(const RunResult& alone, const std::string& alone_dir, const RunResult& twin,
                   const std::string& twin_dir) const {
    EXPECT_EQ(twin.frames, alone.frames);
    EXPECT_EQ(twin.sim_time_s, alone.sim_time_s);
    EXPECT_EQ(twin.points_raw, alone.points_raw);
    EXPECT_EQ(twin.points_filtered, alone.points_filtered);
    EXPECT_EQ(twin.map_voxels, alone.map_voxels);
    EXPECT_EQ(twin.evaluation.mean.f1, alone.evaluation.mean.f1);
    EXPECT_EQ(twin.evaluation.mean.precision, alone.evaluation.mean.precision);
    EXPECT_EQ(twin.evaluation.mean.recall, alone.evaluation.mean.recall);
    EXPECT_EQ(twin.evaluation.mean.snapshots, alone.evaluation.mean.snapshots);
    ASSERT_EQ(twin.checks.size(), alone.checks.size());
    for (std::size_t i = 0; i < twin.checks.size(); ++i) EXPECT_EQ(twin.checks[i].message, alone.checks[i].message);
    for (const char* file : {"map.ply", "costmap.pgm"}) {
      const std::string a = file_bytes(fs::path(alone_dir) / file);
      EXPECT_FALSE(a.empty()) << file;
      EXPECT_EQ(file_bytes(fs::path(twin_dir) / file), a) << file;
    }
  }
  test::WorldFile world_{"wall.xml", test::kRobotBetweenWallsWorld};
};

TEST_F(SharedDriveTest, EachTwinIsItsOwnRun) {
  // STVL's behaviour and the bench's fixes: the edge filter (sensing), ray-cast clearing and floor rounding (layer).
  const std::vector<std::string> fixes = {"map.clearing_mode=raycast", "camera.edge_filter.enabled=true",
                                          "map.mark_rounding=floor"};
  const config::Scenario stvl = scenario({}), ours = scenario(fixes);
  const RunResult stvl_alone = run_scenario(stvl, options("stvl_alone"));
  const RunResult ours_alone = run_scenario(ours, options("ours_alone"));
  const std::vector<RunResult> twins = run_twins({stvl, ours}, {options("stvl_twin"), options("ours_twin")});
  ASSERT_EQ(twins.size(), 2u);
  ASSERT_GT(stvl_alone.frames, 10u);
  // The two behaviours differ on this drive, so a twin given the other's sensing or layer would show.
  ASSERT_NE(stvl_alone.points_raw, ours_alone.points_raw);
  ASSERT_NE(file_bytes(fs::path(options("stvl_alone").out_dir) / "map.ply"),
            file_bytes(fs::path(options("ours_alone").out_dir) / "map.ply"));
  expect_same(stvl_alone, options("stvl_alone").out_dir, twins[0], options("stvl_twin").out_dir);
  expect_same(ours_alone, options("ours_alone").out_dir, twins[1], options("ours_twin").out_dir);
}

TEST_F(SharedDriveTest, ThreeTwinsEachWithItsOwnLayerAndEvaluation) {
  // One twin evaluates more often, one maps at finer voxels, the third is the first again (the same frames twice).
  const config::Scenario a = scenario({"evaluation.evaluate_every_s=0.25"}), b = scenario({"map.voxel_size=0.05"});
  const RunResult a_alone = run_scenario(a, options("a_alone"));
  const RunResult b_alone = run_scenario(b, options("b_alone"));
  const std::vector<RunResult> twins = run_twins({a, b, a}, {options("a_twin"), options("b_twin"), options("a_again")});
  ASSERT_EQ(twins.size(), 3u);
  expect_same(a_alone, options("a_alone").out_dir, twins[0], options("a_twin").out_dir);
  expect_same(b_alone, options("b_alone").out_dir, twins[1], options("b_twin").out_dir);
  expect_same(a_alone, options("a_alone").out_dir, twins[2], options("a_again").out_dir);
}

TEST_F(SharedDriveTest, ATwinsErrorEndsTheDriveAndIsRethrown) {
  // The first twin's bag cannot be written: its loop fails at the start, the other twin ends at its next frame, and
  // the error comes out of run_twins (no hang waiting on the failed twin).
  RunOptions broken = options("broken");
  broken.bag_path = (fs::path(world_.path()).parent_path() / "no_such_folder" / "run.bag").string();
  const config::Scenario s = scenario({});
  EXPECT_ANY_THROW(run_twins({s, s}, {broken, options("fine")}));
}

TEST_F(SharedDriveTest, ClosedLoopOrTimedDrivesAreNotShared) {
  const config::Scenario timed = scenario({"camera.timing.latency_mean_s=0.05"});
  EXPECT_FALSE(can_share_drive(timed));
  EXPECT_TRUE(can_share_drive(scenario({})));
  EXPECT_THAT(test::invalid_argument_of([&] {
                run_twins({timed, timed}, {options("t1"), options("t2")});
              }),
              HasSubstr("closed loop or with camera timing"));
}

TEST(TwinSets, OnlyWhatIsDoneWithTheFrames) {
  for (const char* set : {"map.voxel_size=0.1", "map.observation.max_z=3", "filter.type=csnb", "name=b",
                          "evaluation.tolerance_voxels=2", "checks.f1_3d_min=0.5", "outputs.sample_depth_frames=0",
                          "camera.edge_filter.enabled=true", "cameras[1].edge_filter.enabled=true", "map={}"})
    EXPECT_EQ(twin_sets_problem({set}), "") << set;
  for (const char* set : {"seed=2", "duration_s=5", "camera.noise.enabled=false", "robot.speed_mps=1", "world=w.xml",
                          "mapx.a=1", "names=b", "camera.edge_filterx=1", "cameras[a].edge_filter.x=1",
                          "camera.timing.latency_s=0.1", "navigation.mode=closed_loop"})
    EXPECT_THAT(twin_sets_problem({set}), HasSubstr("may change the drive")) << set;
  EXPECT_THAT(twin_sets_problem({"map.voxel_size"}), HasSubstr("is not KEY=VALUE"));
  EXPECT_THAT(twin_sets_problem({"=1"}), HasSubstr("is not KEY=VALUE"));
}

TEST(TwinSets, ParsedFromOneArgument) {
  const TwinSpec twin = parse_twin("out/b;map.voxel_size=0.1;;camera.edge_filter.enabled=true");
  EXPECT_EQ(twin.out_dir, "out/b");
  EXPECT_EQ(twin.sets, (std::vector<std::string>{"map.voxel_size=0.1", "camera.edge_filter.enabled=true"}));
  EXPECT_TRUE(parse_twin("out/c").sets.empty());
  EXPECT_THAT(test::invalid_argument_of([] { parse_twin(";map.voxel_size=0.1"); }),
              HasSubstr("expected OUT;KEY=VALUE"));
  EXPECT_THAT(test::invalid_argument_of([] { parse_twin("out;seed=3"); }), HasSubstr("'seed' may change the drive"));
}

}  // namespace
}  // namespace stvl::run

// TimedFrames (run/timed_frames.hpp) on the fixture's tiny world: the robot drives at 0.3 m/s toward a wall, its
// 10 Hz camera's frames delayed, re-stamped, dropped; each delivered cloud placed with the pose at its stamp.
#include "run/timed_frames.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "tests/support/fixture.hpp"

namespace stvl::run {
namespace {

// The pipeline's frames up to duration_s, as a run's SimulatedFrames gives them.
class PipelineFrames : public FrameSource {
 public:
  PipelineFrames(pipeline::Pipeline& pipeline, double duration_s) : pipeline_(pipeline), duration_s_(duration_s) {}
  const pipeline::Frame* next() override {
    return pipeline_.next_time_s() > duration_s_ + 1e-9 ? nullptr : &pipeline_.step();
  }
  const std::vector<pipeline::CameraConfig>& cameras() const override { return pipeline_.config().cameras; }
  std::unique_ptr<BagRecorder> open_bag(const std::string&, const BagSettings&, const pipeline::Frame*) override {
    return nullptr;
  }

 private:
  pipeline::Pipeline& pipeline_;
  double duration_s_;
};

struct Delivered {
  double time_s, capture_s, mean_x, base_x, mean_y = 0, camera_y = 0;
  Eigen::Isometry3d T_map_odom = Eigen::Isometry3d::Identity();
};

class TimedFramesTest : public test::MujocoTest {
 protected:
  pipeline::PipelineConfig config() const {
    pipeline::PipelineConfig c;
    c.world_path = world_.path();
    c.path.waypoints_W = {{0.0, 0.0}, {1.5, 0.0}};
    c.path.cruise_speed_mps = 0.3;
    pipeline::CameraConfig& camera = c.cameras.front();
    camera.intrinsics = sensors::CameraIntrinsics::from_hfov(160, 120, 1.2, 0.2, 6.0, 10.0);  // 10 Hz
    camera.noise.enabled = false;
    camera.sources.front().params.clearing = true;
    c.sim.camera_mount.height_m = 0.5;
    c.filter.type = filter::FilterType::kVoxel;
    c.filter.device = filter::Device::kCpu;
    c.filter.voxel.voxel_size_m = 0.05;
    c.map.voxel_size_m = 0.05;
    return c;
  }
  // Every frame a source gives over 1.5 s: its time, the capture time of its cloud (the frame's own pose), the
  // mean x of its decimated cloud, and the robot's x at the frame.
  // lost: every (time, capture time) the lost-frame observer got, and every delivered frame's (time, -1), in order.
  std::vector<Delivered> run(const pipeline::PipelineConfig& c, bool timed, std::vector<CameraTimingStats>* stats,
                             LocalizationStats* localization = nullptr,
                             std::vector<std::pair<double, double>>* lost = nullptr) {
    pipeline::Pipeline pipeline(c);
    PipelineFrames frames(pipeline, 1.5);
    TimedFrames timed_frames(frames, pipeline, 7, 1.5);
    if (lost)
      timed_frames.set_lost_observer(
          [lost](const pipeline::Frame& f, double time_s) { lost->emplace_back(time_s, f.frame_index / 10.0); });
    FrameSource& source = timed ? static_cast<FrameSource&>(timed_frames) : frames;
    std::vector<Delivered> out;
    while (const pipeline::Frame* f = source.next()) {
      if (lost) lost->emplace_back(f->time_s, -1.0);
      const Eigen::Matrix3Xf& cloud = f->observation->decimated_W;
      out.push_back({f->time_s, f->frame_index / 10.0, cloud.cols() ? cloud.row(0).cast<double>().mean() : 0.0,
                     f->observation->T_world_camera.translation().x(),
                     cloud.cols() ? cloud.row(1).cast<double>().mean() : 0.0,
                     f->observation->T_world_camera.translation().y(), f->T_map_odom});
    }
    if (stats) *stats = timed_frames.stats();
    if (localization) *localization = timed_frames.localization();
    return out;
  }
  test::WorldFile world_{"wall.xml", test::kRobotBetweenWallsWorld};
};

TEST_F(TimedFramesTest, TimingThatChangesNothingGivesTheUntimedFrames) {
  pipeline::PipelineConfig c = config();
  c.cameras.front().timing.stamp = sensors::StampMode::kOffset;  // offset 0: stamped at capture
  c.tf.odom_rate_hz = 10.0;                                      // odometry at the camera's own times
  const std::vector<Delivered> plain = run(config(), false, nullptr), timed = run(c, true, nullptr);
  ASSERT_EQ(plain.size(), timed.size());
  ASSERT_EQ(plain.size(), 16u);  // 0 .. 1.5 s at 10 Hz
  for (std::size_t k = 0; k < plain.size(); ++k) {
    EXPECT_EQ(plain[k].time_s, timed[k].time_s);
    EXPECT_EQ(plain[k].mean_x, timed[k].mean_x) << "frame " << k;
  }
}

TEST_F(TimedFramesTest, LateFramesStampedAtCaptureArriveLaterInOrderAndUnmoved) {
  pipeline::PipelineConfig c = config();
  c.cameras.front().timing.latency_mean_s = 0.25;  // odometry at 50 Hz: captures (k / 10) fall on its messages
  std::vector<CameraTimingStats> stats;
  const std::vector<Delivered> plain = run(config(), false, nullptr), late = run(c, true, &stats);
  ASSERT_EQ(late.size(), 13u);  // captures up to 1.2 s; the last three would arrive after 1.5 s
  for (std::size_t k = 0; k < late.size(); ++k) {
    EXPECT_NEAR(late[k].time_s, plain[k].time_s + 0.25, 1e-9);
    EXPECT_NEAR(late[k].mean_x, plain[k].mean_x, 1e-5) << "placed with the pose it was taken at";
  }
  ASSERT_EQ(stats.size(), 1u);
  EXPECT_EQ(stats[0].captured, 16u);
  EXPECT_EQ(stats[0].delivered, 13u);
  EXPECT_EQ(stats[0].after_end, 3u);
  EXPECT_NEAR(stats[0].mean_delay_s, 0.25, 1e-9);
}

TEST_F(TimedFramesTest, StampedAtArrivalTheCloudMovesWithTheRobotsPoseThen) {
  pipeline::PipelineConfig c = config();
  c.cameras.front().timing.latency_mean_s = 0.2;
  c.cameras.front().timing.stamp = sensors::StampMode::kArrival;
  const std::vector<Delivered> plain = run(config(), false, nullptr), smeared = run(c, true, nullptr);
  ASSERT_GE(smeared.size(), 10u);
  std::size_t moving = 0;
  for (std::size_t k = 0; k < smeared.size(); ++k) {
    // frame k's cloud is placed with the camera where it was at k / 10 + 0.2 s: that frame's pose (k + 2) when the
    // untimed run took one there.
    const double shift = plain[k + 2].base_x - plain[k].base_x;
    EXPECT_NEAR(smeared[k].mean_x - plain[k].mean_x, shift, 2e-4)  // float points: a fraction of a millimetre
        << "frame " << k << ": " << smeared[k].mean_x << " vs " << plain[k].mean_x << ", camera " << plain[k].base_x
        << " -> " << plain[k + 2].base_x << ", smeared camera " << smeared[k].base_x;
    moving += shift > 0.03;
  }
  EXPECT_GE(moving, 5u);  // the robot drives: the smear is real, not zero
}

TEST_F(TimedFramesTest, DropsAndTransformTimeoutsAreCountedByReason) {
  pipeline::PipelineConfig c = config();
  c.cameras.front().timing.drop_probability = 1.0;
  std::vector<CameraTimingStats> stats;
  EXPECT_TRUE(run(c, true, &stats).empty());
  EXPECT_EQ(stats[0].dropped.at("camera"), 16u);
  c = config();
  c.tf.odom_latency_s = 0.3;  // > transform_tolerance 0.2: never in time
  EXPECT_TRUE(run(c, true, &stats).empty());
  EXPECT_EQ(stats[0].dropped.at("tf_timeout"), 16u);
  EXPECT_EQ(stats[0].delivered, 0u);
}

TEST_F(TimedFramesTest, EveryLostFrameReachesTheEvaluationInTimeOrder) {
  pipeline::PipelineConfig c = config();
  c.cameras.front().timing.latency_mean_s = 0.15;
  c.cameras.front().timing.drop_probability = 0.5;
  std::vector<CameraTimingStats> stats;
  std::vector<std::pair<double, double>> seen;  // (time, capture time; -1 for a delivered frame)
  const std::vector<Delivered> delivered = run(c, true, &stats, nullptr, &seen);
  const std::size_t lost = seen.size() - delivered.size();
  ASSERT_GT(stats[0].dropped.at("camera"), 2u);
  EXPECT_EQ(lost, stats[0].dropped.at("camera"));
  EXPECT_EQ(delivered.size() + lost + stats[0].after_end, stats[0].captured);
  for (std::size_t k = 0; k < seen.size(); ++k) {
    if (seen[k].second >= 0) {
      EXPECT_NEAR(seen[k].first, seen[k].second, 1e-9) << "known lost at its capture";
    }
    if (k > 0) {
      EXPECT_GE(seen[k].first, seen[k - 1].first - 1e-9) << "the evaluation's clock never runs back";
    }
  }
}

TEST_F(TimedFramesTest, ALocalizationJumpMovesTheMapLayersReadingsNotTheOdomLayers) {
  pipeline::PipelineConfig c = config();
  c.sim.localization.enabled = true;
  c.sim.localization.rate_hz = 10.0;                   // corrections at the camera's own times
  c.sim.localization.jumps = {{0.55, 0.0, 0.2, 0.0}};  // 0.2 m off in y from the correction at 0.6 s on
  LocalizationStats stats;
  const std::vector<Delivered> plain = run(config(), false, nullptr), in_map = run(c, true, nullptr, &stats);
  ASSERT_EQ(plain.size(), in_map.size());
  std::size_t moved = 0;
  for (std::size_t k = 0; k < plain.size(); ++k) {
    const double expected = plain[k].time_s >= 0.6 - 1e-9 ? 0.2 : 0.0;
    EXPECT_NEAR(in_map[k].camera_y - plain[k].camera_y, expected, 2e-3) << "frame " << k;
    EXPECT_NEAR(in_map[k].mean_y - plain[k].mean_y, expected, 2e-3) << "the cloud moves with the camera";
    // The frame's map -> odom is the localizer's: T_map_odom * T_odom_base is the truth moved by the jump.
    EXPECT_NEAR(in_map[k].T_map_odom.translation().y(), expected, 2e-3) << "odometry starts at the truth's origin";
    moved += expected > 0;
  }
  EXPECT_GE(moved, 9u);
  EXPECT_EQ(stats.corrections, 16u);  // 0 .. 1.5 s at 10 Hz
  EXPECT_EQ(stats.jumps, 1u);
  EXPECT_NEAR(stats.max_error_m, 0.2, 2e-3);
  c.sim.localization.layer_in_odom = true;  // the local costmap's frame: the corrections never reach it
  const std::vector<Delivered> in_odom = run(c, true, nullptr);
  ASSERT_EQ(plain.size(), in_odom.size());
  for (std::size_t k = 0; k < plain.size(); ++k) EXPECT_EQ(in_odom[k].mean_y, plain[k].mean_y) << "frame " << k;
}

}  // namespace
}  // namespace stvl::run

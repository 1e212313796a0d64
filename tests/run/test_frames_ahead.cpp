// FramesAhead (run/frames_ahead.hpp) on the fixture's robot between two walls, two noisy cameras of one instant:
// frame for frame what Pipeline::step() gives one after another, the world snapshots included, until the duration.
#include "run/frames_ahead.hpp"

#include <gtest/gtest.h>

#include <cstring>

#include "tests/support/fixture.hpp"

namespace stvl::run {
namespace {

class FramesAheadTest : public test::MujocoTest {
 protected:
  pipeline::PipelineConfig config() const {
    pipeline::PipelineConfig c;
    c.world_path = world_.path();
    c.path.waypoints_W = {{0.0, 0.0}, {1.0, 0.3}};
    c.path.cruise_speed_mps = 0.4;
    pipeline::CameraConfig& front = c.cameras.front();
    front.intrinsics = sensors::CameraIntrinsics::from_hfov(96, 72, 1.2, 0.2, 6.0, 10.0);
    front.noise.enabled = true;
    pipeline::CameraConfig side = front;
    side.name = "side";
    side.sources.front().name = "side_source";
    side.mount.yaw_rad = 0.6;
    c.cameras.push_back(side);
    c.filter.type = filter::FilterType::kVoxel;
    c.filter.device = filter::Device::kCpu;
    return c;
  }
  test::WorldFile world_{"wall.xml", test::kRobotBetweenWallsWorld};
};

bool same_image(const sensors::DepthImage& a, const sensors::DepthImage& b) {
  return a.depth_m.size() == b.depth_m.size() &&
         std::memcmp(a.depth_m.data(), b.depth_m.data(), a.depth_m.size() * sizeof(float)) == 0;
}

TEST_F(FramesAheadTest, GivesTheFramesOfOneStepAfterAnother) {
  constexpr double kDuration_s = 1.0;
  pipeline::Pipeline serial(config()), ahead_pipeline(config());
  FramesAhead ahead(ahead_pipeline, kDuration_s);
  int frames = 0;
  while (serial.next_time_s() <= kDuration_s + 1e-9) {
    const pipeline::Frame& want = serial.step();
    const pipeline::Frame* got = ahead.next();
    ASSERT_NE(got, nullptr) << "frame " << frames;
    EXPECT_EQ(got->camera_index, want.camera_index);
    EXPECT_EQ(got->time_s, want.time_s);
    EXPECT_TRUE(got->T_world_base.isApprox(want.T_world_base, 0.0));
    EXPECT_TRUE(same_image(got->clean_depth, want.clean_depth)) << "frame " << frames;
    EXPECT_TRUE(same_image(got->depth, want.depth)) << "frame " << frames;
    EXPECT_TRUE(got->observation->marking_W.isApprox(want.observation->marking_W, 0.0)) << "frame " << frames;
    ASSERT_EQ(got->cameras_now.size(), want.cameras_now.size());
    EXPECT_EQ(got->cameras_now[1].next_frame_time_s, want.cameras_now[1].next_frame_time_s);
    // The snapshot is the world at this frame, while the pipeline behind it has moved on.
    ASSERT_NE(got->world, nullptr);
    ASSERT_NE(got->world, &ahead_pipeline.simulator().world());
    const int n = 3 * want.world->model()->ngeom;
    EXPECT_EQ(std::memcmp(got->world->data()->geom_xpos, want.world->data()->geom_xpos, n * sizeof(mjtNum)), 0);
    EXPECT_EQ(got->world->time_s(), want.world->time_s());
    ++frames;
  }
  EXPECT_EQ(ahead.next(), nullptr);  // past the duration
  EXPECT_EQ(frames, 2 * 11);         // two cameras at 10 Hz, frames at 0, 0.1, .. 1.0 s
}

}  // namespace
}  // namespace stvl::run

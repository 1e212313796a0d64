// The pipeline with a robot from a URDF (worlds/urdf/example_bot) in place of robot.xml: cameras at its links.
#include "pipeline/pipeline.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>

#include "sim/urdf_robot.hpp"
#include "tests/support/fixture.hpp"
#include "tests/support/invalid_argument.hpp"

namespace stvl::pipeline {
namespace {

using ::testing::HasSubstr;

class PipelineUrdfTest : public test::MujocoTest {
 protected:
  // example_bot, kinematic, between the fixture's walls (wall x 2.5..2.7 ahead), its camera at the optical frame.
  PipelineConfig config() const {
    sim::UrdfRobotConfig robot;
    robot.urdf = test::worlds_dir() + "/urdf/example_bot/example_bot.urdf";
    robot.package_path = {test::worlds_dir() + "/urdf"};
    robot.drive = sim::DriveMode::kKinematic;
    PipelineConfig c;
    c.world_path = world_.path();
    c.urdf_robot = std::make_shared<const sim::UrdfRobot>(sim::build_urdf_robot(robot));
    c.sim.robot = c.urdf_robot->diff_drive_config();
    c.sim.drive = c.urdf_robot->drive;
    c.path.waypoints_W = {{0.0, 0.0}, {1.0, 0.0}};
    c.path.cruise_speed_mps = 0.3;
    CameraConfig& camera = c.cameras.front();
    camera.frame = "camera_depth_optical_frame";
    camera.mount = sim::camera_mount_at(c.urdf_robot->urdf, camera.frame);
    camera.intrinsics = sensors::CameraIntrinsics::from_hfov(160, 120, 1.2, 0.2, 6.0, 10.0);
    camera.noise.enabled = false;
    camera.sources.front().params.horizontal_fov_rad = camera.intrinsics.hfov_rad();
    camera.sources.front().params.vertical_fov_rad = camera.intrinsics.vfov_rad();
    c.filter.device = filter::Device::kCpu;
    return c;
  }
  test::WorldFile world_{"wall.xml", test::kRobotBetweenWallsWorld};
};

TEST_F(PipelineUrdfTest, TheCameraSitsAtItsUrdfLinkAndSeesTheWall) {
  const PipelineConfig c = config();
  Pipeline pipeline(c);
  const Eigen::Isometry3d T_base_optical = c.urdf_robot->urdf.T_root_link("camera_depth_optical_frame");
  for (int k = 0; k < 6; ++k) {
    const Frame& f = pipeline.step();
    ASSERT_TRUE(f.robot_upright);
    EXPECT_TRUE(f.T_world_camera.isApprox(f.T_world_base * T_base_optical, 1e-9)) << k;
    EXPECT_NEAR(f.T_world_base.translation().y(), 0.0, 1e-3);  // the kinematic drive keeps to the path
    // The optical frame looks along the base's x, pitched 0.1 rad down: the wall at x = 2.5 m fills the view.
    ASSERT_GT(f.point_count, 160 * 120 / 2);
    EXPECT_NEAR(f.cloud_W.row(0).maxCoeff(), 2.5, 0.02);
  }
  EXPECT_GT(pipeline.simulator().T_world_base().translation().x(), 0.01);
}

TEST_F(PipelineUrdfTest, OnlyTheCamerasOwnLinkMayHoldIt) {
  // The camera is inside camera_link's housing box: allowed for a camera at that link, not for a bare mount.
  PipelineConfig c = config();
  EXPECT_NO_THROW(Pipeline{c});
  c.cameras.front().frame.clear();
  EXPECT_THAT(test::invalid_argument_of([&] { Pipeline{c}; }),
              HasSubstr("camera 'camera': mounted inside the robot's body (geom 'camera_link_collision')"));
}

}  // namespace
}  // namespace stvl::pipeline

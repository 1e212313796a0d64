// sim/urdf_robot.hpp, robot_description/urdf_mjcf.hpp and the kinematic drive: a URDF robot standing in for robot.xml.
#include <gtest/gtest.h>

#include <cmath>

#include "sim/simulator.hpp"
#include "sim/urdf_robot.hpp"
#include "tests/robot_description/urdf_texts.hpp"
#include "tests/sim/polyline.hpp"
#include "tests/support/fixture.hpp"
#include "tests/support/invalid_argument.hpp"

namespace stvl::sim {
namespace {

using test::invalid_argument_of;
using test::TempFolder;
using test::tiny_bot_urdf;

constexpr double kOnPath_m = 0.001;  // the kinematic drive's promise: the base within 1 mm of the path

// tiny_bot written to a fresh folder and built with `drive`; the folder also holds the test world.
struct TinyBot {
  explicit TinyBot(DriveMode drive = DriveMode::kAuto, const std::string& text = tiny_bot_urdf()) {
    config.urdf = dir.write("tiny_bot.urdf", text);
    config.drive = drive;
    world_path = dir.write("world.xml", test::kUrdfFloorWorld);
  }
  UrdfRobot build() const { return build_urdf_robot(config); }
  TempFolder dir;
  UrdfRobotConfig config;
  std::string world_path;
};

Simulator simulator(const TinyBot& bot, const UrdfRobot& robot) {
  SimulatorConfig config;
  config.robot = robot.diff_drive_config();
  config.drive = robot.drive;
  return Simulator(load_world_with_robot(bot.world_path, robot), config);
}

using test::off_polyline;

TEST(UrdfRobot, FindsTheWheelsWithTheirRadiusAndTrack) {
  const TinyBot bot(DriveMode::kPhysics);
  const UrdfRobot robot = bot.build();
  EXPECT_EQ(robot.wheels.left_joint, "left_wheel_joint");
  EXPECT_EQ(robot.wheels.right_joint, "right_wheel_joint");
  EXPECT_FALSE(robot.wheels.named);
  EXPECT_NEAR(robot.wheels.radius_m, 0.06, 1e-12);
  EXPECT_NEAR(robot.wheels.track_width_m, 0.36, 1e-12);
  // Wheels and caster reach 0.06 m below base_link: it rests 0.06 m (plus robot.xml's 2 mm) above the floor.
  EXPECT_NEAR(robot.rest_height_m, 0.062, 1e-9);
  EXPECT_NEAR(robot.mass_kg, 5.65, 1e-9);
  // The footprint: the box (x +-0.2, y +-0.15) and the wheels (to y +-0.2, x +-0.06).
  Eigen::AlignedBox2d box;
  for (const auto& p : robot.footprint_B) box.extend(p);
  EXPECT_NEAR(box.min().x(), -0.2, 1e-9);
  EXPECT_NEAR(box.max().x(), 0.2, 1e-9);
  EXPECT_NEAR(box.max().y(), 0.2, 1e-9);
  EXPECT_NEAR(box.min().y(), -0.2, 1e-9);
}

TEST(UrdfRobot, NamedWheelsOverrideRadiusAndSeparation) {
  TinyBot bot(DriveMode::kKinematic);
  bot.config.wheels = {"left_wheel_joint", "right_wheel_joint", 0.07, 0.4};
  const UrdfRobot robot = bot.build();
  EXPECT_TRUE(robot.wheels.named);
  EXPECT_DOUBLE_EQ(robot.wheels.radius_m, 0.07);
  EXPECT_DOUBLE_EQ(robot.wheels.track_width_m, 0.4);
  bot.config.wheels.left_joint = "caster_joint";
  const std::string message = invalid_argument_of([&] { bot.build(); });
  EXPECT_NE(message.find("robot.wheels.left: no continuous or revolute joint named 'caster_joint' (candidates: "
                         "left_wheel_joint (axis [0.00, 1.00, 0.00] in the base, y 0.180 m), right_wheel_joint"),
            std::string::npos)
      << message;
}

TEST(UrdfRobot, WheelsNotFoundNameTheCandidates) {
  std::string text = tiny_bot_urdf();
  for (const std::string axis : {"\"0 1 0\"", "\"0 -1 0\""}) text.replace(text.find(axis), axis.size(), "\"1 0 0\"");
  const TinyBot bot(DriveMode::kKinematic, text);
  const std::string message = invalid_argument_of([&] { bot.build(); });
  EXPECT_NE(message.find("no left wheel joint found. A wheel is a continuous or revolute joint on the base whose axis "
                         "lies along the base's y"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("left_wheel_joint (axis [1.00, 0.00, 0.00] in the base, y 0.180 m)"), std::string::npos)
      << message;
  EXPECT_NE(message.find("robot.wheels: {left: JOINT, right: JOINT}"), std::string::npos) << message;
}

TEST(UrdfRobot, OpticalFrameLooksAlongTheBasesX) {
  const UrdfRobot robot = TinyBot(DriveMode::kKinematic).build();
  // Through camera_link -> camera_depth_optical_frame: the optical z (the view) along base +x, x right (-y), y down.
  for (const std::string frame : {"camera_depth_optical_frame", "camera_link"}) {
    const CameraMount mount = camera_mount_at(robot.urdf, frame);
    const Eigen::Isometry3d T = T_base_camera_link(mount) * DiffDriveRobot::T_camera_link_optical();
    EXPECT_TRUE(T.linear().col(2).isApprox(Eigen::Vector3d::UnitX(), 1e-12)) << frame;
    EXPECT_TRUE(T.linear().col(0).isApprox(-Eigen::Vector3d::UnitY(), 1e-12)) << frame;
    EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(0.15, 0, 0.3), 1e-12)) << frame;
  }
  EXPECT_TRUE(is_optical_frame("camera_depth_optical_frame"));
  EXPECT_FALSE(is_optical_frame("camera_link"));
  const std::string message = invalid_argument_of([&] { camera_mount_at(robot.urdf, "camera_depth_frame"); });
  EXPECT_NE(message.find("no link named 'camera_depth_frame' (links, nearest first: camera_depth_optical_frame"),
            std::string::npos)
      << message;
}

TEST(UrdfRobot, AutoDriveIsKinematicForAMasslessUrdf) {
  const UrdfRobot robot = TinyBot(DriveMode::kAuto, tiny_bot_urdf(false)).build();
  EXPECT_EQ(robot.drive, DriveMode::kKinematic);
  EXPECT_NE(robot.drive_reason.find("auto: no usable inertial on the base or a wheel (base_link: no <inertial>"),
            std::string::npos)
      << robot.drive_reason;
}

TEST(UrdfRobot, AutoDriveIsKinematicWhenTheProbeFails) {
  // tiny_bot with its base's mass 0.15 m ahead of the axle, where nothing holds it up: it tips onto its nose.
  std::string text = tiny_bot_urdf();
  const std::string com = "-0.05 0 0.05";
  text.replace(text.find(com), com.size(), "0.15 0 0.05");
  const UrdfRobot robot = TinyBot(DriveMode::kAuto, text).build();
  EXPECT_EQ(robot.drive, DriveMode::kKinematic);
  EXPECT_EQ(robot.drive_reason.rfind("auto: the physics probe failed: the robot tilted by ", 0), 0u)
      << robot.drive_reason;
}

TEST(UrdfRobot, AutoDriveIsPhysicsWhenTheProbeDrives) {
  const UrdfRobot robot = TinyBot(DriveMode::kAuto).build();
  EXPECT_EQ(robot.drive, DriveMode::kPhysics) << robot.drive_reason;
  EXPECT_NE(robot.drive_reason.find("auto: the physics probe drove a 1.5 m path"), std::string::npos)
      << robot.drive_reason;
}

TEST(UrdfRobot, PhysicsDrivesForwardOnBothWheels) {
  // The right wheel's URDF axis is -y: written along +y, a positive rate drives forward on both sides.
  const TinyBot bot(DriveMode::kPhysics);
  Simulator sim = simulator(bot, bot.build());
  sim.set_start_pose({0, 0, 0});
  sim.set_path({{{0, 0}, {1.5, 0}}, 0.5});
  while (!sim.path_finished() && sim.time_s() < 10) sim.step();
  EXPECT_TRUE(sim.path_finished());
  EXPECT_NEAR(sim.T_world_base().translation().x(), 1.5, 0.06);
  EXPECT_LT(sim.robot().tilt_rad(), 0.05);
}

TEST(UrdfRobot, KinematicDriveKeepsTheBaseOnThePath) {
  const TinyBot bot(DriveMode::kKinematic, tiny_bot_urdf(false));
  const UrdfRobot robot = bot.build();
  Simulator sim = simulator(bot, robot);
  const Path path{{{0, 0}, {2, 0}, {2, 1.5}, {0.5, 2}}, 0.6};
  sim.set_start_pose({0, 0, 0});
  sim.set_path(path);
  double worst = 0, worst_z = 0;
  while (!sim.path_finished() && sim.time_s() < 30) {
    sim.step();
    const Eigen::Isometry3d T = sim.T_world_base();
    worst = std::max(worst, off_polyline(path.waypoints_W, T.translation().head<2>()));
    worst_z = std::max(worst_z, std::abs(T.translation().z() - robot.rest_height_m));
  }
  EXPECT_TRUE(sim.path_finished());
  EXPECT_LT(worst, kOnPath_m);
  EXPECT_LT(worst_z, 1e-9);
  EXPECT_LT((sim.T_world_base().translation().head<2>() - Eigen::Vector2d(0.5, 2)).norm(), kOnPath_m);
  // The wheels turned for the distance driven (odometry from their rates agrees with the path).
  EXPECT_NEAR(sim.odometry().x_m(), 0.5, 0.01);
  EXPECT_NEAR(sim.odometry().y_m(), 2.0, 0.01);
}

TEST(UrdfRobot, WorldWithoutTheRobotIncludeIsAnError) {
  const TinyBot bot(DriveMode::kKinematic);
  const std::string world = bot.dir.write("bare.xml", "<mujoco><worldbody/></mujoco>");
  const std::string message = invalid_argument_of([&] { load_world_with_robot(world, bot.build()); });
  EXPECT_NE(message.find("has no <include file=\"robot.xml\"/> for the URDF robot"), std::string::npos) << message;
}

TEST(UrdfRobot, ExampleBotFromTheWorldsFolder) {
  UrdfRobotConfig config;
  config.urdf = test::worlds_dir() + "/urdf/example_bot/example_bot.urdf";
  config.package_path = {test::worlds_dir() + "/urdf"};
  const UrdfRobot robot = build_urdf_robot(config);
  EXPECT_EQ(robot.urdf.root, "base_footprint");
  EXPECT_EQ(robot.drive, DriveMode::kPhysics) << robot.drive_reason;
  EXPECT_NEAR(robot.wheels.radius_m, 0.05, 1e-12);
  EXPECT_NEAR(robot.wheels.track_width_m, 0.32, 1e-12);
  EXPECT_NEAR(robot.rest_height_m, 0.002, 1e-6);  // base_footprint on the floor
  const CameraMount mount = camera_mount_at(robot.urdf, "camera_depth_optical_frame");
  EXPECT_NEAR(mount.height_m, 0.49, 1e-12);
  EXPECT_NEAR(mount.pitch_rad, 0.1, 1e-12);
}

}  // namespace
}  // namespace stvl::sim

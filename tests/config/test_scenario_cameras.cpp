// robot.cameras: several cameras, each with its mount, sensor keys and observation overrides.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "tests/config/scenario_texts.hpp"

namespace stvl::config {
namespace {

using ::testing::HasSubstr;
using namespace test;

constexpr double kDeg = M_PI / 180.0;

const std::string kTwoCameras = R"(name: two
world: w.xml
robot:
  waypoints: [[0, 0], [1, 0]]
  speed_mps: 0.5
  cameras:
    - name: front
      mount: {xyz_m: [0.15, 0.0, 0.5], pitch_deg: 20}
      rate_hz: 15
    - name: back
      mount: {xyz_m: [-0.2, 0.05, 0.4], roll_deg: 1, pitch_deg: 10, yaw_deg: 180}
      preset: d435_640x480
      rate_hz: 6
      noise: {enabled: false}
      observation: {obstacle_range: 1.5, horizontal_fov_angle: 1.0}
map:
  observation:
    obstacle_range: 3.0
    max_z: 4.0
)";

TEST(ScenarioCameras, EachCameraHasItsMountSensorAndSource) {
  const Scenario s = parse(kTwoCameras);
  ASSERT_EQ(s.pipeline.cameras.size(), 2u);
  const auto& front = s.pipeline.cameras[0];
  const auto& back = s.pipeline.cameras[1];
  EXPECT_EQ(front.name, "front");
  EXPECT_DOUBLE_EQ(front.mount.forward_offset_m, 0.15);
  EXPECT_DOUBLE_EQ(front.mount.height_m, 0.5);
  EXPECT_NEAR(front.mount.pitch_rad, 20 * kDeg, 1e-12);
  EXPECT_EQ(back.name, "back");
  EXPECT_DOUBLE_EQ(back.mount.forward_offset_m, -0.2);
  EXPECT_DOUBLE_EQ(back.mount.lateral_offset_m, 0.05);
  EXPECT_NEAR(back.mount.roll_rad, 1 * kDeg, 1e-12);
  EXPECT_NEAR(back.mount.yaw_rad, M_PI, 1e-12);
  EXPECT_EQ(back.intrinsics.width, 640);
  EXPECT_DOUBLE_EQ(back.intrinsics.rate_hz, 6.0);
  EXPECT_TRUE(front.noise.enabled);
  EXPECT_FALSE(back.noise.enabled);
  // One source per camera, named after it: map.observation, the camera's own FOV, then its overrides.
  ASSERT_EQ(front.sources.size(), 1u);
  EXPECT_EQ(front.sources[0].name, "front");
  EXPECT_TRUE(front.sources[0].params.marking && front.sources[0].params.clearing);
  EXPECT_DOUBLE_EQ(front.sources[0].params.obstacle_range_m, 3.0);
  EXPECT_DOUBLE_EQ(front.sources[0].params.horizontal_fov_rad, front.intrinsics.hfov_rad());
  EXPECT_DOUBLE_EQ(back.sources[0].params.obstacle_range_m, 1.5);
  EXPECT_DOUBLE_EQ(back.sources[0].params.max_z_m, 4.0);
  EXPECT_DOUBLE_EQ(back.sources[0].params.horizontal_fov_rad, 1.0);
  EXPECT_DOUBLE_EQ(back.sources[0].params.vertical_fov_rad, back.intrinsics.vfov_rad());
  EXPECT_EQ(evaluation_config(s).cameras, 2u);
}

TEST(ScenarioCameras, ADefaultScenarioHasOneCameraNamedCamera) {
  const Scenario s = parse(kMinimal);
  ASSERT_EQ(s.pipeline.cameras.size(), 1u);
  EXPECT_EQ(s.camera().name, "camera");
  EXPECT_EQ(s.camera().sources.at(0).name, "camera");
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return text.replace(pos, from.size(), to);
}

TEST(ScenarioCameras, BadCamerasNameLineAndKey) {
  EXPECT_THAT(error_of(replaced(kTwoCameras, "name: back", "name: front")),
              HasSubstr(at(10, "robot.cameras[1].name") + "two cameras are named 'front'"));
  EXPECT_THAT(error_of(replaced(kTwoCameras, "[0.15, 0.0, 0.5]", "[0.15, 0.0, -0.1]")),
              HasSubstr(at(8, "robot.cameras[0].mount.xyz_m") + "z must be > 0 m"));
  EXPECT_THAT(error_of(replaced(kTwoCameras, "roll_deg: 1,", "rol_deg: 1,")),
              HasSubstr(at(11, "robot.cameras[1].mount.rol_deg") + "unknown key; did you mean 'roll_deg'?"));
  EXPECT_THAT(error_of(replaced(kTwoCameras, "      mount: {xyz_m: [0.15, 0.0, 0.5], pitch_deg: 20}\n", "")),
              HasSubstr("robot.cameras[0].mount: required mapping is missing"));
  EXPECT_THAT(error_of(replaced(kTwoCameras, "obstacle_range: 1.5", "obstacle_range: -1")),
              HasSubstr(at(15, "robot.cameras[1].observation.obstacle_range")));
  EXPECT_THAT(error_of(replaced(kTwoCameras, "  cameras:\n", "  camera_mount: {height_m: 0.5}\n  cameras:\n")),
              HasSubstr("robot.camera_mount: give each camera its mount in robot.cameras instead"));
  EXPECT_THAT(error_of(kTwoCameras + "camera: {rate_hz: 15}\n"),
              HasSubstr("camera: robot.cameras gives the cameras; move these keys into its entries"));
  EXPECT_THAT(error_of(replaced(kTwoCameras, "map:\n  observation:\n    obstacle_range: 3.0\n    max_z: 4.0\n",
                                "map:\n  ros_params: /some/params.yaml\n")),
              HasSubstr(at(15, "robot.cameras[1].observation") + "the sources come from map.ros_params"));
  EXPECT_THAT(error_of(replaced(kTwoCameras, "  cameras:\n", "  cameras: []\n  old:\n")),
              HasSubstr("robot.cameras: expected at least one camera"));
}

TEST(ScenarioCameras, EdgeFilterIsOffByDefaultAndReadPerCamera) {
  EXPECT_FALSE(parse(kMinimal).camera().edge_filter.enabled);
  const Scenario one =
      parse(std::string(kMinimal) + "camera:\n  edge_filter: {enabled: true, max_jump_at_1m_m: 0.05}\n");
  EXPECT_TRUE(one.camera().edge_filter.enabled);
  EXPECT_DOUBLE_EQ(one.camera().edge_filter.max_jump_at_1m_m, 0.05);
  const Scenario two = parse(replaced(kTwoCameras, "      noise: {enabled: false}\n",
                                      "      noise: {enabled: false}\n      edge_filter: {enabled: true}\n"));
  EXPECT_FALSE(two.pipeline.cameras[0].edge_filter.enabled);
  EXPECT_TRUE(two.pipeline.cameras[1].edge_filter.enabled);
  EXPECT_DOUBLE_EQ(two.pipeline.cameras[1].edge_filter.max_jump_at_1m_m,
                   sensors::DepthEdgeFilterConfig{}.max_jump_at_1m_m);
  // Bad thresholds and unknown keys name the line and the dotted key.
  for (const char* bad : {"-0.03", "0", ".nan", ".inf"}) {
    SCOPED_TRACE(bad);
    EXPECT_THAT(
        error_of(replaced(
            kTwoCameras, "      noise: {enabled: false}\n",
            "      noise: {enabled: false}\n      edge_filter: {max_jump_at_1m_m: " + std::string(bad) + "}\n")),
        HasSubstr(at(15, "robot.cameras[1].edge_filter.max_jump_at_1m_m") + "DepthEdgeFilterConfig: max_jump_at_1m_m"));
  }
  EXPECT_THAT(error_of(std::string(kMinimal) + "camera:\n  edge_filter: {enabled: true, jump_m: 0.1}\n"),
              HasSubstr(at(7, "camera.edge_filter.jump_m") + "unknown key"));
}

}  // namespace
}  // namespace stvl::config

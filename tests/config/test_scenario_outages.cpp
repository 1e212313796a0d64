// Camera outages (robot.cameras[i].outages, camera.outages) and STVL's source buffer keys.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "tests/config/scenario_texts.hpp"

namespace stvl::config {
namespace {

using ::testing::HasSubstr;
using namespace test;

// Line 9 holds front's outages, line 11 back's.
const std::string kOutages = R"(name: outages
world: w.xml
duration_s: 10
robot:
  waypoints: [[0, 0], [1, 0]]
  speed_mps: 0.5
  cameras:
    - name: front
      outages: [{from_s: 6, to_s: 8}, {from_s: 2, to_s: 3.5}]
      mount: {xyz_m: [0.15, 0.0, 0.5], pitch_deg: 20}
    - name: back
      mount: {xyz_m: [-0.2, 0.05, 0.4], yaw_deg: 180}
      observation: {expected_update_rate: 0.5, observation_persistence: 0.3}
)";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return text.replace(pos, from.size(), to);
}

TEST(ScenarioOutages, EachCameraReadsItsOutagesSorted) {
  const Scenario s = parse(kOutages);
  const auto& front = s.pipeline.cameras.at(0);
  ASSERT_EQ(front.outages.size(), 2u);
  EXPECT_DOUBLE_EQ(front.outages[0].from_s, 2.0);
  EXPECT_DOUBLE_EQ(front.outages[0].to_s, 3.5);
  EXPECT_DOUBLE_EQ(front.outages[1].from_s, 6.0);
  EXPECT_DOUBLE_EQ(front.outages[1].to_s, 8.0);
  EXPECT_TRUE(s.pipeline.cameras.at(1).outages.empty());
  // STVL's buffer keys: the camera's own, else map.observation's, else STVL's 0.
  EXPECT_DOUBLE_EQ(s.pipeline.cameras[1].sources[0].params.expected_update_rate_s, 0.5);
  EXPECT_DOUBLE_EQ(s.pipeline.cameras[1].sources[0].params.observation_persistence_s, 0.3);
  EXPECT_DOUBLE_EQ(front.sources[0].params.expected_update_rate_s, 0.0);
  EXPECT_DOUBLE_EQ(front.sources[0].params.observation_persistence_s, 0.0);
}

TEST(ScenarioOutages, TheOneCameraFormHasThemToo) {
  const Scenario s = parse(std::string(kMinimal) + "camera: {outages: [{from_s: 1, to_s: 2}]}\n");
  ASSERT_EQ(s.camera().outages.size(), 1u);
  EXPECT_DOUBLE_EQ(s.camera().outages[0].to_s, 2.0);
}

TEST(ScenarioOutages, BadOutagesNameLineAndKey) {
  const std::string front = "robot.cameras[0].outages";
  EXPECT_THAT(error_of(replaced(kOutages, "{from_s: 6, to_s: 8}", "{from_s: 8, to_s: 8}")),
              HasSubstr(at(9, front + "[0].to_s") + "must be finite and > from_s"));
  EXPECT_THAT(error_of(replaced(kOutages, "{from_s: 6, to_s: 8}", "{from_s: 7, to_s: 6}")),
              HasSubstr(at(9, front + "[0].to_s") + "must be finite and > from_s"));
  EXPECT_THAT(error_of(replaced(kOutages, "{from_s: 6, to_s: 8}", "{from_s: 6, to_s: 12}")),
              HasSubstr(at(9, front + "[0].to_s") + "must be <= duration_s"));
  EXPECT_THAT(error_of(replaced(kOutages, "{from_s: 6, to_s: 8}", "{from_s: -1, to_s: 1}")),
              HasSubstr(at(9, front + "[0].from_s") + "must be finite and >= 0 s"));
  EXPECT_THAT(error_of(replaced(kOutages, "{from_s: 6, to_s: 8}", "{from_s: .nan, to_s: 1}")),
              HasSubstr(at(9, front + "[0].from_s") + "must be finite and >= 0 s"));
  EXPECT_THAT(error_of(replaced(kOutages, "{from_s: 6, to_s: 8}", "{from_s: 6, to_s: .inf}")),
              HasSubstr(at(9, front + "[0].to_s") + "must be finite"));
  EXPECT_THAT(error_of(replaced(kOutages, "{from_s: 2, to_s: 3.5}", "{from_s: 7.5, to_s: 9}")),
              HasSubstr(at(9, front + "[1].from_s") + "overlaps outages[0] [6.000000, 8.000000) s"));
  EXPECT_THAT(error_of(replaced(kOutages, "{from_s: 2, to_s: 3.5}", "{from_s: 2, until_s: 3.5}")),
              HasSubstr(front + "[1].to_s: required key is missing"));
  EXPECT_THAT(error_of(replaced(kOutages, "expected_update_rate: 0.5", "expected_update_rate: -0.5")),
              HasSubstr(at(13, "robot.cameras[1].observation.expected_update_rate") + "expected_update_rate"));
  EXPECT_THAT(error_of(replaced(kOutages, "observation_persistence: 0.3", "observation_persistence: .inf")),
              HasSubstr(at(13, "robot.cameras[1].observation.observation_persistence")));
  // drop_when_not_current (ours) means nothing without an expected_update_rate.
  EXPECT_THAT(error_of(kOutages + "map:\n  observation: {drop_when_not_current: true}\n"),
              HasSubstr(at(15, "map.observation.drop_when_not_current") + "needs expected_update_rate > 0 s"));
  const Scenario dropping = parse(replaced(kOutages, "observation_persistence: 0.3", "drop_when_not_current: true"));
  EXPECT_TRUE(dropping.pipeline.cameras[1].sources[0].params.drop_when_not_current);
  EXPECT_FALSE(dropping.pipeline.cameras[0].sources[0].params.drop_when_not_current);
}

}  // namespace
}  // namespace stvl::config

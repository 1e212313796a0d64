// Lint across camera timing and the layer's parameters (config/timing_lint.hpp), on hand-computed waits.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "config/scenario.hpp"
#include "config/timing_lint.hpp"
#include "tests/config/scenario_texts.hpp"

namespace stvl::config {
namespace {

using ::testing::HasSubstr;

Scenario with(const std::string& extra) { return parse_scenario(std::string(test::kMinimal) + extra, "s.yaml", "."); }

TEST(TimingLint, NoTimingNoFindings) { EXPECT_TRUE(lint_timing(with("")).empty()); }

TEST(TimingLint, ASlowCameraWithoutTimingStillMeetsExpectedUpdateRate) {
  // STVL #333: a 2 Hz camera, readings 0.5 s apart, against expected_update_rate 0.3 s.
  const auto findings = lint_timing(with("camera: {rate_hz: 2}\nmap: {observation: {expected_update_rate: 0.3}}\n"));
  ASSERT_EQ(findings.size(), 1u);
  EXPECT_THAT(findings[0].what_stvl_does, HasSubstr("every 0.500 s"));
  EXPECT_EQ(findings[0].write_instead.rfind("expected_update_rate: 0.75", 0), 0u);
}

TEST(TimingLint, ToleranceBelowEveryWaitDropsEveryReading) {
  // Odometry at 20 Hz, 0.2 s late; frames 0.05 s late, stamped at capture: a reading waits 0.2 - 0.05 = 0.15 s
  // (a message right at its stamp) to 0.05 + 0.2 - 0.05 = 0.2 s. Tolerance 0.1: every reading dropped; fix 0.20.
  const auto findings =
      lint_timing(with("camera: {timing: {latency_mean_s: 0.05}}\n"
                       "tf: {odom_rate_hz: 20, odom_latency_s: 0.2, transform_tolerance: 0.1}\n"));
  ASSERT_EQ(findings.size(), 1u);
  EXPECT_EQ(findings[0].key, "tf.transform_tolerance");
  EXPECT_THAT(findings[0].what_stvl_does, HasSubstr("wait 0.150 to 0.200 s"));
  EXPECT_THAT(findings[0].what_stvl_does, HasSubstr("drops every reading"));
  EXPECT_EQ(findings[0].write_instead.rfind("transform_tolerance: 0.20", 0), 0u);
}

TEST(TimingLint, ToleranceInsideTheWaitsDropsSomeAndStampsAtArrivalWaitLonger) {
  // Stamped at arrival the reading waits for the message after its arrival: 0 + 0.2 to 0.05 + 0.2 = 0.25 s.
  const auto findings =
      lint_timing(with("camera: {timing: {latency_mean_s: 0.05, stamp: arrival}}\n"
                       "tf: {odom_rate_hz: 20, odom_latency_s: 0.2, transform_tolerance: 0.22}\n"));
  ASSERT_EQ(findings.size(), 1u);
  EXPECT_THAT(findings[0].what_stvl_does, HasSubstr("wait 0.200 to 0.250 s"));
  EXPECT_THAT(findings[0].what_stvl_does, HasSubstr("the readings that wait longer"));
  EXPECT_EQ(findings[0].write_instead.rfind("transform_tolerance: 0.25", 0), 0u);
  // Enough tolerance: nothing.
  EXPECT_TRUE(lint_timing(with("camera: {timing: {latency_mean_s: 0.05, stamp: arrival}}\n"
                               "tf: {odom_rate_hz: 20, odom_latency_s: 0.2, transform_tolerance: 0.25}\n"))
                  .empty());
}

TEST(TimingLint, ExpectedUpdateRateShorterThanTheGapBetweenReadings) {
  // A 2 Hz camera (STVL #333) with jitter 0.02: readings up to 0.5 + 0.12 s apart; expected_update_rate 0.3.
  const auto findings =
      lint_timing(with("camera: {rate_hz: 2, timing: {latency_mean_s: 0.1, latency_jitter_s: 0.02}}\n"
                       "map: {observation: {expected_update_rate: 0.3}}\n"));
  ASSERT_EQ(findings.size(), 1u);
  EXPECT_THAT(findings[0].key, HasSubstr("expected_update_rate"));
  EXPECT_THAT(findings[0].what_stvl_does, HasSubstr("up to 0.620 s apart"));
  EXPECT_EQ(findings[0].write_instead.rfind("expected_update_rate: 0.93", 0), 0u);  // 1.5 x 0.62
}

TEST(TimingLint, PersistenceShorterThanTheAgeOnArrivalDropsEveryReading) {
  // Frames 0.3 s late, stamped at capture; odometry at 50 Hz, 0.02 s late: a reading is 0.3 s old (0.3 >= 0.02 +
  // 0.02) when it reaches the layer. observation_persistence 0.2: every one goes on arrival; fix 0.3 + 0.2 = 0.50.
  const auto findings =
      lint_timing(with("camera: {timing: {latency_mean_s: 0.3}}\n"
                       "tf: {odom_rate_hz: 50, odom_latency_s: 0.02, transform_tolerance: 0.5}\n"
                       "map: {observation: {observation_persistence: 0.2}}\n"));
  ASSERT_EQ(findings.size(), 1u);
  EXPECT_THAT(findings[0].key, HasSubstr("observation_persistence"));
  EXPECT_THAT(findings[0].what_stvl_does, HasSubstr("0.300 to 0.300 s old"));
  EXPECT_THAT(findings[0].what_stvl_does, HasSubstr("drops every reading"));
  EXPECT_EQ(findings[0].write_instead.rfind("observation_persistence: 0.50", 0), 0u);
  // Stamped at arrival a reading is as old as its wait for odometry (0.02 to 0.04 s): 0.2 keeps it.
  EXPECT_TRUE(lint_timing(with("camera: {timing: {latency_mean_s: 0.3, stamp: arrival}}\n"
                               "tf: {odom_rate_hz: 50, odom_latency_s: 0.02, transform_tolerance: 0.5}\n"
                               "map: {observation: {observation_persistence: 0.2}}\n"))
                  .empty());
  // Persistence 0 keeps the newest whatever its age.
  EXPECT_TRUE(lint_timing(with("camera: {timing: {latency_mean_s: 0.3}}\n"
                               "tf: {odom_rate_hz: 50, odom_latency_s: 0.02, transform_tolerance: 0.5}\n"))
                  .empty());
}

}  // namespace
}  // namespace stvl::config

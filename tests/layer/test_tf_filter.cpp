// tf's timing and the message filter (layer/tf_filter.hpp) on hand-computed times.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "layer/tf_filter.hpp"

namespace stvl::layer {
namespace {

TEST(TfFilter, ALookupWaitsForTheFirstMessageAtOrAfterTheStamp) {
  TfTimingConfig c;                                           // odom at 50 Hz, no latency
  EXPECT_NEAR(transform_available_s(c, 1.005), 1.02, 1e-12);  // between the messages of 1.00 and 1.02
  EXPECT_NEAR(transform_available_s(c, 1.02), 1.02, 1e-12);   // on a message: that one
  c.odom_latency_s = 0.1;
  EXPECT_NEAR(transform_available_s(c, 1.005), 1.12, 1e-12);
  EXPECT_TRUE(std::isinf(transform_available_s(c, -0.01)));  // before the first message: never
}

TEST(TfFilter, AReadingWaitsUpToTransformToleranceThenIsDropped) {
  TfTimingConfig c;
  c.odom_rate_hz = 20.0, c.odom_latency_s = 0.15, c.transform_tolerance_s = 0.2;
  // Captured at 1.01 and stamped there, arriving at 1.04: its transform (message 1.05) arrives at 1.20, 0.16 s
  // after the reading: it waits and goes at 1.20.
  FilterVerdict v = message_filter(c, 1.04, 1.01);
  ASSERT_TRUE(v.delivered());
  EXPECT_NEAR(v.delivered_s, 1.20, 1e-12);
  // With a tolerance of 0.1 s it is dropped (ROS 2 logs "for reason 'Unknown'").
  c.transform_tolerance_s = 0.1;
  v = message_filter(c, 1.04, 1.01);
  EXPECT_EQ(v.reason, DropReason::kTfTimeout);
  EXPECT_STREQ(to_string(v.reason), "tf_timeout");
  // Stamped at arrival (1.04): the message of 1.05 still, the same wait.
  EXPECT_EQ(message_filter(c, 1.04, 1.04).reason, DropReason::kTfTimeout);
  // A transform already there: delivered on arrival.
  c.odom_latency_s = 0.0;
  v = message_filter(c, 1.2, 1.01);
  EXPECT_TRUE(v.delivered());
  EXPECT_DOUBLE_EQ(v.delivered_s, 1.2);
}

TEST(TfFilter, BadSettingsNameTheirKey) {
  TfTimingConfig c;
  c.odom_rate_hz = 0.0;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = {};
  c.odom_latency_s = NAN;
  try {
    c.validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("odom_latency_s"), std::string::npos);
  }
  c = {};
  c.transform_tolerance_s = -1;
  EXPECT_THROW(c.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace stvl::layer

// A camera's timing (sensors/camera_timing.hpp): latency, stamps and lost frames, counter-based and seeded.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "sensors/camera_timing.hpp"

namespace stvl::sensors {
namespace {

TEST(CameraTiming, APerfectCameraArrivesAtCaptureStampedAtCapture) {
  const CameraTimingConfig perfect;
  EXPECT_FALSE(perfect.enabled());
  const FrameTiming t = frame_timing(perfect, 1, 7, 0.5);
  EXPECT_FALSE(t.dropped);
  EXPECT_DOUBLE_EQ(t.arrival_s, 0.5);
  EXPECT_DOUBLE_EQ(t.stamp_s, 0.5);
}

TEST(CameraTiming, StampModes) {
  CameraTimingConfig c;
  c.latency_mean_s = 0.08;
  EXPECT_DOUBLE_EQ(frame_timing(c, 1, 0, 1.0).stamp_s, 1.0);  // capture
  EXPECT_DOUBLE_EQ(frame_timing(c, 1, 0, 1.0).arrival_s, 1.08);
  c.stamp = StampMode::kArrival;
  EXPECT_DOUBLE_EQ(frame_timing(c, 1, 0, 1.0).stamp_s, 1.08);
  c.stamp = StampMode::kOffset;
  c.stamp_offset_s = -0.03;
  EXPECT_DOUBLE_EQ(frame_timing(c, 1, 0, 1.0).stamp_s, 0.97);
  EXPECT_EQ(parse_stamp_mode("arrival"), StampMode::kArrival);
  EXPECT_THROW(parse_stamp_mode("header"), std::invalid_argument);
}

TEST(CameraTiming, JitterHasTheGivenSpreadAndNeverGoesBelowZero) {
  CameraTimingConfig c;
  c.latency_mean_s = 0.1, c.latency_jitter_s = 0.02;
  double sum = 0, sq = 0;
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    const double latency = frame_timing(c, 3, k, 0.0).arrival_s;
    sum += latency, sq += latency * latency;
  }
  const double mean = sum / n, sd = std::sqrt(sq / n - mean * mean);
  EXPECT_NEAR(mean, 0.1, 0.001);  // standard error 0.00014
  EXPECT_NEAR(sd, 0.02, 0.001);
  c.latency_mean_s = 0.0;  // half the draws would be negative: cut at 0
  for (int k = 0; k < 1000; ++k) EXPECT_GE(frame_timing(c, 3, k, 2.0).arrival_s, 2.0);
}

TEST(CameraTiming, DropsComeInBurstsAtTheGivenRate) {
  CameraTimingConfig c;
  c.drop_probability = 0.01, c.drop_burst_frames = 5;
  int dropped = 0, runs = 0;
  bool previous = false;
  const int n = 100000;
  for (int k = 0; k < n; ++k) {
    const bool d = frame_timing(c, 9, k, k / 15.0).dropped;
    dropped += d;
    if (d && !previous) ++runs;
    previous = d;
  }
  // A frame is lost when one of the 5 frames up to it started a burst: 1 - 0.99^5 = 4.90 % of frames.
  EXPECT_NEAR(dropped / double(n), 1.0 - std::pow(0.99, 5), 0.003);
  EXPECT_GT(dropped / double(runs), 4.0);  // bursts of 5 frames, merged where they overlap
  // Same seed and frame, same fate; another seed, other frames.
  int same = 0, differ = 0;
  for (int k = 0; k < 2000; ++k) {
    same += frame_timing(c, 9, k, 0).dropped == frame_timing(c, 9, k, 0).dropped;
    differ += frame_timing(c, 9, k, 0).dropped != frame_timing(c, 10, k, 0).dropped;
  }
  EXPECT_EQ(same, 2000);
  EXPECT_GT(differ, 0);
}

TEST(CameraTiming, BadValuesNameTheirKey) {
  const auto error = [](auto change) {
    CameraTimingConfig c;
    change(c);
    try {
      c.validate();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error([](auto& c) { c.latency_mean_s = -0.1; }).find("latency_mean_s"), std::string::npos);
  EXPECT_NE(error([](auto& c) { c.latency_jitter_s = NAN; }).find("latency_jitter_s"), std::string::npos);
  EXPECT_NE(error([](auto& c) { c.drop_probability = 1.5; }).find("drop_probability"), std::string::npos);
  EXPECT_NE(error([](auto& c) { c.drop_burst_frames = 0; }).find("drop_burst_frames"), std::string::npos);
  EXPECT_NE(error([](auto& c) { c.stamp_offset_s = 0.1; }).find("stamp_offset_s"), std::string::npos);
  EXPECT_EQ(error([](auto&) {}), "");
}

}  // namespace
}  // namespace stvl::sensors

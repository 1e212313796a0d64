// The localizer's corrections (sim/localization.hpp): their index in time, their error (noise per correction,
// seeded; jumps from their time on), and the config's limits.
#include "sim/localization.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace stvl::sim {
namespace {

TEST(Localization, TheCorrectionInForceIsTheLastPublished) {
  LocalizationConfig c;
  c.rate_hz = 4.0;  // corrections at 0, 0.25, 0.5 ...
  EXPECT_EQ(correction_index(c, -1.0), 0u);
  EXPECT_EQ(correction_index(c, 0.0), 0u);
  EXPECT_EQ(correction_index(c, 0.24), 0u);
  EXPECT_EQ(correction_index(c, 0.25), 1u);
  EXPECT_EQ(correction_index(c, 1.0), 4u);
}

TEST(Localization, AJumpHoldsFromItsTimeUntilTheNext) {
  LocalizationConfig c;
  c.rate_hz = 10.0;
  c.jumps = {{1.0, 0.3, -0.1, 0.05}, {2.05, 0.0, 0.0, 0.0}};
  const PoseError2 before = localization_error(c, 1, 9), at = localization_error(c, 1, 10);
  EXPECT_EQ(before.x_m, 0.0);
  EXPECT_EQ(at.x_m, 0.3);
  EXPECT_EQ(at.y_m, -0.1);
  EXPECT_EQ(at.yaw_rad, 0.05);
  EXPECT_EQ(localization_error(c, 1, 20).x_m, 0.3);  // 2.0 s: the second jump (2.05 s) not yet
  EXPECT_EQ(localization_error(c, 1, 21).x_m, 0.0);  // put right at the first correction after it
}

TEST(Localization, NoiseIsSeededPerCorrectionWithItsStandardDeviation) {
  LocalizationConfig c;
  c.noise_xy_m = 0.05;
  c.noise_yaw_rad = 0.01;
  double sum = 0, sum2 = 0, sum_yaw2 = 0;
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    const PoseError2 e = localization_error(c, 42, k);
    sum += e.x_m, sum2 += e.x_m * e.x_m, sum_yaw2 += e.yaw_rad * e.yaw_rad;
  }
  EXPECT_NEAR(sum / n, 0.0, 0.002);
  EXPECT_NEAR(std::sqrt(sum2 / n), 0.05, 0.002);
  EXPECT_NEAR(std::sqrt(sum_yaw2 / n), 0.01, 0.0004);
  EXPECT_EQ(localization_error(c, 42, 7).x_m, localization_error(c, 42, 7).x_m);
  EXPECT_NE(localization_error(c, 42, 7).x_m, localization_error(c, 43, 7).x_m);
  EXPECT_NE(localization_error(c, 42, 7).x_m, localization_error(c, 42, 7).y_m);
}

TEST(Localization, ValidateNamesTheKey) {
  const auto message = [](const LocalizationConfig& c) {
    try {
      c.validate(10.0);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  LocalizationConfig c;
  EXPECT_EQ(message(c), "");
  c.rate_hz = 0;
  EXPECT_NE(message(c).find("rate_hz"), std::string::npos);
  c = {};
  c.noise_xy_m = NAN;
  EXPECT_NE(message(c).find("noise_xy_m"), std::string::npos);
  c = {};
  c.jumps = {{10.0, 0.1, 0, 0}};
  EXPECT_NE(message(c).find("jumps[0].at_s"), std::string::npos) << "a jump at or after the run's end";
  c.jumps = {{2.0, 0.1, 0, 0}, {1.0, 0, 0, 0}};
  EXPECT_NE(message(c).find("jumps[1].at_s"), std::string::npos) << "out of time order";
  c.jumps = {{2.0, 0.1, 0, 4.0}};
  EXPECT_NE(message(c).find("jumps[0].yaw_rad"), std::string::npos);
}

}  // namespace
}  // namespace stvl::sim

#include <gtest/gtest.h>

#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include "common/format.hpp"
#include "common/statistics.hpp"
#include "common/stopwatch.hpp"
#include "common/units.hpp"

namespace stvl {
namespace {

std::string streamed_fixed(double value, int decimals) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(decimals) << value;
  return text.str();
}

std::string streamed(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

TEST(Format, FixedWritesWhatStdFixedWrote) {
  EXPECT_EQ(fixed(0.9871, 4), "0.9871");
  EXPECT_EQ(fixed(0.5, 0), "0");  // round half to even, as printf
  EXPECT_EQ(fixed(-0.0001, 2), "-0.00");
  EXPECT_EQ(fixed(1e300, 2).size(), 304u);
  for (double v : {0.0, -0.0, 1.0 / 3.0, -2.5, 12.345, 1e-9, 123456789.125, 1e20,
                   std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()})
    for (int decimals : {0, 1, 2, 3, 4, 6})
      EXPECT_EQ(fixed(v, decimals), streamed_fixed(v, decimals)) << v << " with " << decimals;
}

TEST(Format, GeneralWritesWhatOstreamWrote) {
  for (double v : {0.0, -0.0, 0.05, 1e6, 1234567.0, 3.14159265, -1e-7, 2.5, std::numeric_limits<double>::infinity()})
    EXPECT_EQ(general(v), streamed(v)) << v;
  EXPECT_EQ(general(3.14159265, 4), "3.142");
}

TEST(Statistics, MedianOfOddAndEvenCounts) {
  EXPECT_EQ(median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_EQ(median({4.0, 1.0, 3.0, 2.0}), 2.5);
  EXPECT_TRUE(std::isnan(median({})));
  EXPECT_EQ(median({}, 0.0), 0.0);
}

TEST(Stopwatch, CountsUpAndAddsItsScope) {
  const Stopwatch watch;
  double total_ms = 1.0;
  { const ScopedMsTimer timer(total_ms); }
  EXPECT_GE(total_ms, 1.0);
  EXPECT_GE(watch.elapsed_ms(), 0.0);
  EXPECT_NEAR(watch.elapsed_s() * kMsPerSecond, watch.elapsed_ms(), 1e3);
}

TEST(Units, ConversionsAreTheLiteralsTheyReplace) {
  EXPECT_EQ(kSecondsPerNanosecond, 1e-9);
  EXPECT_EQ(kTimeEpsilon_s, 1e-9);
  EXPECT_EQ(degrees(1.0), 1.0 * 180.0 / M_PI);
  EXPECT_EQ(2.0 * kRadPerDeg, 2.0 * (M_PI / 180.0));
}

}  // namespace
}  // namespace stvl

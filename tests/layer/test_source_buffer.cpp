// STVL's measurement buffer on hand-made times: what an update applies, when a source is current.
#include "layer/source_buffer.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace stvl::layer {
namespace {

std::shared_ptr<const Observation> at(double time_s) {
  auto r = std::make_shared<Observation>();
  r->time_s = time_s;
  return r;
}

std::vector<double> times(const SourceBuffer& b) {
  std::vector<double> t;
  for (const auto& r : b.readings()) t.push_back(r->time_s);
  return t;
}

TEST(SourceBuffer, PersistenceZeroKeepsTheLatestForever) {
  SourceBuffer b(0.0, 0.0);
  EXPECT_TRUE(b.readings().empty());
  b.receive(at(0.0));
  b.receive(at(0.1));
  EXPECT_EQ(times(b), (std::vector<double>{0.1}));
  // Nothing arrives for 10 s: STVL still applies the 0.1 s reading at every update.
  EXPECT_EQ(times(b), (std::vector<double>{0.1}));
}

TEST(SourceBuffer, PersistenceCountsFromTheLastReadingNotFromNow) {
  SourceBuffer b(0.25, 0.0);
  for (double t : {0.0, 0.1, 0.2, 0.3}) b.receive(at(t));
  EXPECT_EQ(times(b), (std::vector<double>{0.3, 0.2, 0.1}));  // 0.3 - 0.0 > 0.25 dropped, 0.3 - 0.1 kept
  // A gap: ages still count from the newest reading, so a 5 s old reading is kept until a newer one arrives.
  b.receive(at(5.3));
  EXPECT_EQ(times(b), (std::vector<double>{5.3}));
}

TEST(SourceBuffer, PersistenceAgesEachReadingFromItsHeaderStamp) {
  // Readings delivered 0.2 s after their capture stamp (camera timing): STVL ages them by header.stamp against the
  // last reception, so with persistence 0.25 s a reading is gone once the next arrives; from the newest, the first
  // one too old goes with every one after it, the newest itself when it arrived too late.
  const auto late = [](double stamp_s, double time_s) {
    auto r = std::make_shared<Observation>();
    r->time_s = time_s, r->stamp_s = stamp_s;
    return std::shared_ptr<const Observation>(r);
  };
  SourceBuffer b(0.25, 0.0);
  b.receive(late(0.0, 0.2));
  b.receive(late(0.1, 0.3));
  EXPECT_EQ(times(b), (std::vector<double>{0.3}));  // 0.3 - 0.0 > 0.25: by time_s it would stay
  b.receive(late(0.3, 0.4));
  EXPECT_EQ(times(b), (std::vector<double>{0.4}));  // 0.4 - 0.1 > 0.25 cuts the older one
  b.receive(late(0.2, 0.5));
  EXPECT_TRUE(b.readings().empty()) << "0.5 - 0.2 > 0.25: the newest goes too, as RemoveStaleObservations does";
}

TEST(SourceBuffer, CurrentWhileTheLastReadingIsNoOlderThanTheExpectedPeriod) {
  SourceBuffer b(0.0, 0.5);     // expected_update_rate 0.5: seconds, not Hz
  EXPECT_TRUE(b.current(0.5));  // since the buffer's creation at 0
  EXPECT_FALSE(b.current(0.51));
  b.receive(at(1.0));
  EXPECT_TRUE(b.current(1.5));  // STVL: <= is current
  EXPECT_FALSE(b.current(1.5001));
  EXPECT_TRUE(source_current(100.0, 1.0, 0.0));  // 0: never checked
  EXPECT_FALSE(source_current(1.6, 1.0, 0.5));
}

TEST(SourceBuffer, StaleSpanBetweenTwoReadings) {
  const auto span = stale_span(1.0, 3.0, 0.5);
  ASSERT_TRUE(span.has_value());
  EXPECT_DOUBLE_EQ(span->from_s, 1.5);
  EXPECT_DOUBLE_EQ(span->to_s, 3.0);
  EXPECT_FALSE(stale_span(1.0, 1.5, 0.5).has_value());   // exactly the period: still current
  EXPECT_FALSE(stale_span(1.0, 30.0, 0.0).has_value());  // never checked
}

}  // namespace
}  // namespace stvl::layer

// nav2's ObservationBuffer and ObstacleLayer marking / updateBounds (layer/nav2_observation_buffer.hpp,
// layer/nav2_obstacle_layer.hpp) on hand-made clouds: the limits exactly where nav2's comparisons put them, and
// issue #5476 (an obstacle cleared when the robot reverses past obstacle_max_range) before and after PR #5697.
#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <vector>

#include "layer/nav2_obstacle_layer.hpp"

namespace stvl::layer::nav2 {
namespace {

constexpr std::int64_t kSecond = 1000000000;

Eigen::Matrix3Xf cloud(std::initializer_list<Eigen::Vector3f> ps) {
  Eigen::Matrix3Xf m(3, static_cast<Eigen::Index>(ps.size()));
  Eigen::Index i = 0;
  for (const auto& p : ps) m.col(i++) = p;
  return m;
}

std::vector<double> stamps_s(const Nav2ObservationBuffer& b) {
  std::vector<double> s;
  for (const auto& o : b.observations()) s.push_back(static_cast<double>(o->stamp_ns) / kSecond);
  return s;
}

// ---------------------------------------------------------------------------------------------- ObservationBuffer

TEST(Nav2ObservationBuffer, TheBandKeepsBothLimitsWithFloatZ) {
  Nav2SourceParams p;
  p.min_obstacle_height_m = 0.25;
  p.max_obstacle_height_m = 0.5;
  p.obstacle_max_range_m = 1.5;
  p.raytrace_min_range_m = 0.1;
  Nav2ObservationBuffer b(p, 0);
  const float above = std::nextafter(0.5f, 1.f), below = std::nextafter(0.25f, 0.f);
  b.buffer_cloud({1, 2, 3}, cloud({{0, 0, 0.25f}, {1, 0, 0.5f}, {2, 0, above}, {3, 0, below}, {4, 0, 0.375f}}), 0, 0);
  const Nav2Observation& o = *b.observations().front();
  ASSERT_EQ(o.cloud_W.cols(), 3);  // 0.25 and 0.5 kept (<=, >=), the floats just outside dropped
  EXPECT_EQ(o.cloud_W(0, 0), 0.f);
  EXPECT_EQ(o.cloud_W(0, 1), 1.f);
  EXPECT_EQ(o.cloud_W(0, 2), 4.f);
  EXPECT_EQ(o.origin_W, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(o.obstacle_max_range_m, 1.5);  // the source's ranges travel with the observation
  EXPECT_EQ(o.raytrace_min_range_m, 0.1);
  EXPECT_EQ(o.raytrace_max_range_m, 3.0);  // nav2's default

  // z is compared as the cloud's float: 0.1f = 0.10000000149 is above a max of 0.1 (double) and not below a min.
  p.min_obstacle_height_m = 0.0;
  p.max_obstacle_height_m = 0.1;
  Nav2ObservationBuffer low(p, 0);
  low.buffer_cloud({0, 0, 0}, cloud({{0, 0, 0.1f}}), 0, 0);
  EXPECT_EQ(low.observations().front()->cloud_W.cols(), 0);
  p.min_obstacle_height_m = 0.1;
  p.max_obstacle_height_m = 1.0;
  Nav2ObservationBuffer high(p, 0);
  high.buffer_cloud({0, 0, 0}, cloud({{0, 0, 0.1f}}), 0, 0);
  EXPECT_EQ(high.observations().front()->cloud_W.cols(), 1);
}

TEST(Nav2ObservationBuffer, KeepTimeZeroKeepsTheLatestOnlyAndUnderANanosecondIsZero) {
  EXPECT_EQ(ros_ns_from_seconds(1e-10), 0);  // 0.1 ns truncated
  for (double keep_s : {0.0, 1e-10}) {
    Nav2SourceParams p;
    p.observation_persistence_s = keep_s;
    p.max_obstacle_height_m = 1;
    Nav2ObservationBuffer b(p, 0);
    for (int i = 0; i < 3; ++i) b.buffer_cloud({0, 0, 0}, cloud({}), i * kSecond, i * kSecond);
    EXPECT_EQ(stamps_s(b), (std::vector<double>{2.0})) << keep_s;
    // Still there, whatever its age.
    std::vector<std::shared_ptr<const Nav2Observation>> got;
    b.get_observations(100 * kSecond, got);
    EXPECT_EQ(got.size(), 1u);
  }
}

TEST(Nav2ObservationBuffer, KeepTimeIsStrictInIntegerNanoseconds) {
  // 0.4 - 0.1 = 0.30000000000000004 > 0.3 in doubles, but rclcpp compares nanoseconds: 300000000 is not > 300000000.
  EXPECT_GT(0.4 - 0.1, 0.3);
  EXPECT_EQ(ros_ns_from_seconds(0.4) - ros_ns_from_seconds(0.1), ros_ns_from_seconds(0.3));
  Nav2SourceParams p;
  p.observation_persistence_s = 0.3;
  p.max_obstacle_height_m = 1;
  Nav2ObservationBuffer b(p, 0);
  b.buffer_cloud({0, 0, 0}, cloud({}), ros_ns_from_seconds(0.1), ros_ns_from_seconds(0.1));
  b.purge_stale(ros_ns_from_seconds(0.4));  // age exactly the keep time: kept
  EXPECT_EQ(b.observations().size(), 1u);
  b.purge_stale(ros_ns_from_seconds(0.4) + 1);  // 1 ns older: gone
  EXPECT_TRUE(b.observations().empty());

  // Ages from now, not from the last reading (STVL's): with nothing new, getObservations drops them.
  Nav2SourceParams q = p;
  q.observation_persistence_s = 1.0;
  Nav2ObservationBuffer c(q, 0);
  for (double t : {0.0, 0.5, 1.0}) c.buffer_cloud({0, 0, 0}, cloud({}), ros_ns_from_seconds(t), ros_ns_from_seconds(t));
  std::vector<std::shared_ptr<const Nav2Observation>> got(1);  // appended after what is there
  c.get_observations(ros_ns_from_seconds(1.5), got);           // ages 0.5, 1.0 (kept), 1.5 (dropped)
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(got[0], nullptr);
  EXPECT_EQ(got[1]->stamp_ns, kSecond);  // last received first
  EXPECT_EQ(got[2]->stamp_ns, kSecond / 2);

  // A negative keep time makes everything stale, the observation just buffered too.
  q.observation_persistence_s = -1.0;
  Nav2ObservationBuffer never(q, 0);
  never.buffer_cloud({0, 0, 0}, cloud({}), 0, 0);
  EXPECT_TRUE(never.observations().empty());
}

TEST(Nav2ObservationBuffer, JazzyCutsAtTheFirstStaleOneMainRemovesEach) {
  // Keep 0.5 s. Received in this order: stamp 1.0 at 1.0, stamp 0.6 at 1.05 (late, age 0.45: kept), stamp 1.2 at
  // 1.2. At 1.2 the list (front first) is 1.2 (age 0), 0.6 (age 0.6, stale), 1.0 (age 0.2).
  for (PurgeRule rule : {PurgeRule::kJazzy, PurgeRule::kMain}) {
    Nav2SourceParams p;
    p.observation_persistence_s = 0.5;
    p.max_obstacle_height_m = 1;
    Nav2ObservationBuffer b(p, 0, rule);
    const auto ns = ros_ns_from_seconds;
    b.buffer_cloud({0, 0, 0}, cloud({}), ns(1.0), ns(1.0));
    b.buffer_cloud({0, 0, 0}, cloud({}), ns(0.6), ns(1.05));
    EXPECT_EQ(stamps_s(b), (std::vector<double>{0.6, 1.0}));
    b.buffer_cloud({0, 0, 0}, cloud({}), ns(1.2), ns(1.2));
    // Jazzy erases from 0.6 to the end, 1.0 with it; main removes 0.6 alone.
    const std::vector<double> kept =
        rule == PurgeRule::kJazzy ? std::vector<double>{1.2} : std::vector<double>{1.2, 1.0};
    EXPECT_EQ(stamps_s(b), kept);
  }
}

TEST(Nav2ObservationBuffer, CurrentWhileNowMinusTheReceptionIsAtMostTheRate) {
  Nav2SourceParams p;
  p.expected_update_rate_s = 0.5;
  p.max_obstacle_height_m = 1;
  Nav2ObservationBuffer b(p, 0);  // created at 0: last updated then
  EXPECT_TRUE(b.is_current(kSecond / 2));
  EXPECT_FALSE(b.is_current(kSecond / 2 + 1));
  // Stamped 0 but received at 5 s: the reception counts.
  b.buffer_cloud({0, 0, 0}, cloud({}), 0, 5 * kSecond);
  EXPECT_EQ(b.last_updated_ns(), 5 * kSecond);
  EXPECT_TRUE(b.is_current(5 * kSecond + kSecond / 2));
  EXPECT_FALSE(b.is_current(5 * kSecond + kSecond / 2 + 1));
  p.expected_update_rate_s = 0.0;  // always current
  EXPECT_TRUE(Nav2ObservationBuffer(p, 0).is_current(1000 * kSecond));
}

// ---------------------------------------------------------------------------------------------------- marking

// A 20 x 20 grid at 0.25 m from (0, 0); the sensor at (0.125, 0.125, 0), cell (0, 0); obstacle_max_range 1.0 m
// (4 cells), obstacle_min_range as given (0.5 m: 2 cells). Whether the one point marks its cell.
bool marks(const Eigen::Vector3f& point, MarkingRange rule, double max_m = 1.0, double min_m = 0.0,
           const Eigen::Vector3d& origin = {0.125, 0.125, 0.0}, ObstacleMarkingParams params = {}) {
  CellGrid g(20, 20, 0.25, 0.0, 0.0);
  Nav2Observation obs;
  obs.origin_W = origin;
  obs.cloud_W = cloud({point});
  obs.obstacle_max_range_m = max_m;
  obs.obstacle_min_range_m = min_m;
  params.range_rule = rule;
  Bounds bounds;
  const std::size_t n = mark_observation(g, obs, params, bounds);
  unsigned mx = 0, my = 0;
  const bool lethal = world_to_map(g, point.x(), point.y(), mx, my) && g.cost(mx, my) == kLethalObstacle;
  EXPECT_EQ(n, lethal ? 1u : 0u);
  if (lethal) {
    EXPECT_EQ(bounds.max_x_m, static_cast<double>(point.x()));  // touched at the point, not the cell
  }
  return lethal;
}

constexpr MarkingRange k3d = MarkingRange::kWorld3d, kCells = MarkingRange::kCells,
                       kNow = MarkingRange::kCellsAndWorld2d;

TEST(Nav2Marking, MaxRangeAtItsLimitsUnderEachRule) {
  // Exactly 1.0 m (1.125 - 0.125), cell 4 = the 4 cells: before #5697 >= skips it; the cell rules keep it (4 <= 4)
  // and #6092's prefilter too (1.0 is not > 1.0).
  EXPECT_FALSE(marks({1.125f, 0.125f, 0}, k3d));
  EXPECT_TRUE(marks({1.125f, 0.125f, 0}, kCells));
  EXPECT_TRUE(marks({1.125f, 0.125f, 0}, kNow));
  // 1.075 m, still cell 4: only #5697 alone marks it (the case #6092 fixed for issue #6084).
  EXPECT_FALSE(marks({1.2f, 0.125f, 0}, k3d));
  EXPECT_TRUE(marks({1.2f, 0.125f, 0}, kCells));
  EXPECT_FALSE(marks({1.2f, 0.125f, 0}, kNow));
  // Cell 5: past 4 cells for all.
  EXPECT_FALSE(marks({1.25f, 0.125f, 0}, kCells));
  EXPECT_FALSE(marks({1.25f, 0.125f, 0}, kNow));
  // Diagonal cell (3, 3): hypot 4.24 truncates to 4, marked by cells; 1.06 m in the world, not by the prefilter.
  EXPECT_FALSE(marks({0.875f, 0.875f, 0}, k3d));
  EXPECT_TRUE(marks({0.875f, 0.875f, 0}, kCells));
  EXPECT_FALSE(marks({0.875f, 0.875f, 0}, kNow));
  // 0.75 m away in x, 0.75 m up: 1.06 m in 3D (before #5697: too far), 0.75 m in 2D (after: marked).
  EXPECT_FALSE(marks({0.875f, 0.125f, 0.75f}, k3d));
  EXPECT_TRUE(marks({0.875f, 0.125f, 0.75f}, kCells));
  EXPECT_TRUE(marks({0.875f, 0.125f, 0.75f}, kNow));
}

TEST(Nav2Marking, MinRangeAtItsLimitsUnderEachRule) {
  // obstacle_min_range 0.5 m = 2 cells. Exactly 0.5 m, cell 2: not < for any rule.
  for (MarkingRange rule : {k3d, kCells, kNow}) EXPECT_TRUE(marks({0.625f, 0.125f, 0}, rule, 10.0, 0.5));
  // 0.375 m but cell 2: too close in metres (before, and #6092), not in cells (#5697 alone).
  EXPECT_FALSE(marks({0.5f, 0.125f, 0}, k3d, 10.0, 0.5));
  EXPECT_TRUE(marks({0.5f, 0.125f, 0}, kCells, 10.0, 0.5));
  EXPECT_FALSE(marks({0.5f, 0.125f, 0}, kNow, 10.0, 0.5));
  // Cell 1 < 2.
  EXPECT_FALSE(marks({0.375f, 0.125f, 0}, kCells, 10.0, 0.5));
}

TEST(Nav2Marking, HeightLimitsAreMarkedAndTheOriginMustBeOnTheGridSince5697) {
  ObstacleMarkingParams band;
  band.min_obstacle_height_m = 0.25;
  band.max_obstacle_height_m = 0.5;
  const Eigen::Vector3d o{0.125, 0.125, 0.0};
  EXPECT_TRUE(marks({0.625f, 0.125f, 0.25f}, kNow, 1.0, 0.0, o, band));  // z < min skips: min marks
  EXPECT_TRUE(marks({0.625f, 0.125f, 0.5f}, kNow, 1.0, 0.0, o, band));   // z > max skips: max marks
  EXPECT_FALSE(marks({0.625f, 0.125f, std::nextafter(0.5f, 1.f)}, kNow, 1.0, 0.0, o, band));
  EXPECT_FALSE(marks({0.625f, 0.125f, std::nextafter(0.25f, 0.f)}, kNow, 1.0, 0.0, o, band));
  // The sensor just left of the grid, the point 0.5 m away on it: marked before #5697, skipped after.
  const Eigen::Vector3d off{-0.125, 0.125, 0.0};
  EXPECT_TRUE(marks({0.375f, 0.125f, 0}, k3d, 1.0, 0.0, off));
  EXPECT_FALSE(marks({0.375f, 0.125f, 0}, kCells, 1.0, 0.0, off));
  EXPECT_FALSE(marks({0.375f, 0.125f, 0}, kNow, 1.0, 0.0, off));
}

// ----------------------------------------------------------------------------------------------- updateBounds

Nav2SourceParams source(bool marking, bool clearing) {
  Nav2SourceParams p;
  p.max_obstacle_height_m = 1.0;
  p.marking = marking;
  p.clearing = clearing;
  return p;
}

TEST(Nav2UpdateBounds, ClearsEveryClearingObservationBeforeMarking) {
  // 20 x 3 at 0.25 m, unknown; the sensor at (0.125, 0.375), cell (0, 1).
  CellGrid g(20, 3, 0.25, 0.0, 0.0, kNoInformation);
  Nav2ObservationBuffer marking(source(true, false), 0), clearing(source(false, true), 0);
  marking.buffer_cloud({0.125, 0.375, 0.2}, cloud({{1.125f, 0.375f, 0.2f}}), 0, 0);   // cell (4, 1)
  clearing.buffer_cloud({0.125, 0.375, 0.2}, cloud({{2.125f, 0.375f, 0.2f}}), 0, 0);  // cell (8, 1), past (4, 1)
  Bounds bounds;
  EXPECT_TRUE(update_bounds(g, {&marking}, {&clearing}, 0, {}, bounds));
  // The ray freed cells 0..8 of row 1 (its end too); the mark at 4 came after and stays.
  for (unsigned x = 0; x <= 8; ++x) EXPECT_EQ(g.cost(x, 1), x == 4 ? kLethalObstacle : kFreeSpace) << x;
  EXPECT_EQ(g.cost(9, 1), kNoInformation);
  EXPECT_EQ(g.cost(4, 0), kNoInformation);
  // Bounds: the origin, the ray's end (2.125, within 3.0 m), the mark.
  EXPECT_DOUBLE_EQ(bounds.min_x_m, 0.125);
  EXPECT_DOUBLE_EQ(bounds.max_x_m, 2.125);
  EXPECT_DOUBLE_EQ(bounds.min_y_m, 0.375);
  EXPECT_DOUBLE_EQ(bounds.max_y_m, 0.375);
}

TEST(Nav2UpdateBounds, AStaleMarkingBufferSkipsAllClearing) {
  // Both buffers got a cloud at 0; the marking one expects one every 0.5 s, the clearing one has no rate.
  for (const std::int64_t now : {kSecond / 2, kSecond / 2 + 1}) {
    CellGrid g(20, 3, 0.25, 0.0, 0.0, kLethalObstacle);
    Nav2SourceParams mp = source(true, false);
    mp.expected_update_rate_s = 0.5;
    Nav2ObservationBuffer marking(mp, 0), clearing(source(false, true), 0);
    marking.buffer_cloud({0.125, 0.375, 0.2}, cloud({{4.125f, 0.375f, 0.2f}}), 0, 0);  // cell (16, 1): out of 2.5 m
    clearing.buffer_cloud({0.125, 0.375, 0.2}, cloud({{2.125f, 0.375f, 0.2f}}), 0, 0);
    Bounds bounds;
    const bool current = update_bounds(g, {&marking}, {&clearing}, now, {}, bounds);
    EXPECT_EQ(current, now == kSecond / 2);  // at exactly the rate still current
    // At 0.5 s the ray frees cells 0..8; 1 ns later nav2 never gathers the clearing observations: nothing freed.
    EXPECT_EQ(g.cost(3, 1), now == kSecond / 2 ? kFreeSpace : kLethalObstacle);
  }
}

// Issue #5476: obstacle_max_range = raytrace_max_range = 1.0 m (10 cells at 0.1 m), one marking and clearing
// source, keep time 0. The obstacle at (1.85, 0.55), cell (18, 5); the sensor reverses from x 1.05 (cell 10)
// to 0.81 (cell 8, 1.04 m away) to 0.71 (cell 7, 1.14 m). The obstacle's cell after each update.
std::vector<std::uint8_t> reverse_away(MarkingRange rule, double raytrace_max_range_m = 1.0) {
  CellGrid g(40, 10, 0.1, 0.0, 0.0);
  Nav2SourceParams p = source(true, true);
  p.obstacle_max_range_m = 1.0;
  p.raytrace_max_range_m = raytrace_max_range_m;
  Nav2ObservationBuffer b(p, 0);
  ObstacleMarkingParams params;
  params.range_rule = rule;
  std::vector<std::uint8_t> obstacle;
  std::int64_t now = 0;
  for (double sensor_x : {1.05, 0.81, 0.71}) {
    now += kSecond / 10;
    b.buffer_cloud({sensor_x, 0.55, 0.2}, cloud({{1.85f, 0.55f, 0.2f}}), now, now);
    Bounds bounds;
    update_bounds(g, {&b}, {&b}, now, params, bounds);
    obstacle.push_back(g.cost(18, 5));
  }
  return obstacle;
}

TEST(Nav2UpdateBounds, Issue5476ReversingPastTheMaxRange) {
  constexpr std::uint8_t L = kLethalObstacle, F = kFreeSpace;
  // 0.8 m: marked by all. 1.04 m, cells 18 - 8 = 10: the ray (dist 10, max 10 cells, scale 1) clears cell 18.
  // Before #5697 marking (1.04^2 >= 1) skips it: the obstacle is gone, and stays gone at 1.14 m.
  EXPECT_EQ(reverse_away(k3d), (std::vector<std::uint8_t>{L, F, F}));
  // #5697: cell distance 10 <= 10 marks it again after the clearing; at 11 cells neither the ray (10 of 11 steps)
  // reaches it nor marking: it persists.
  EXPECT_EQ(reverse_away(kCells), (std::vector<std::uint8_t>{L, L, L}));
  // #6092's prefilter skips 1.04 m > 1.0 m while the ray still reaches cell 18: #5476 again inside the last cell.
  EXPECT_EQ(reverse_away(kNow), (std::vector<std::uint8_t>{L, F, F}));
  // raytrace_max_range 3.0 > obstacle_max_range: past the marking range, clearing reaches the obstacle under every
  // rule (the PR's "keep the observed cell" was reverted before the merge).
  EXPECT_EQ(reverse_away(kCells, 3.0), (std::vector<std::uint8_t>{L, L, F}));
  EXPECT_EQ(reverse_away(k3d, 3.0), (std::vector<std::uint8_t>{L, F, F}));
}

}  // namespace
}  // namespace stvl::layer::nav2

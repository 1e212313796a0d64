#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>

#include "bench/synthetic_corridor.hpp"
#include "filter/csnb.hpp"
#include "filter/detail/common.hpp"
#include "helpers.hpp"

namespace stvl::filter {
namespace {

std::set<std::uint32_t> occupied_cubes(const Eigen::Matrix3Xf& points, const detail::CsnbLayout& layout) {
  std::set<std::uint32_t> cubes;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    if (points.col(i).allFinite()) cubes.insert(detail::cube_key(layout, points(0, i), points(1, i), points(2, i)));
  }
  return cubes;
}

// Checks the documented guarantee by brute force: every kept point has at most max_neighbours kept
// neighbours, except anchors, which may exceed it only through other anchors (one per cube); the output is
// a subset of the input and every occupied cube keeps a point.
void check_csnb(const Eigen::Matrix3Xf& in, const Eigen::Matrix3Xf& out, const CsnbConfig& config) {
  const detail::CsnbLayout layout = detail::make_csnb_layout(detail::compute_bounds(in, 1), config);
  EXPECT_EQ(occupied_cubes(in, layout), occupied_cubes(out, layout));
  std::set<std::tuple<float, float, float>> input;
  for (Eigen::Index i = 0; i < in.cols(); ++i) input.insert({in(0, i), in(1, i), in(2, i)});
  for (Eigen::Index i = 0; i < out.cols(); ++i) ASSERT_TRUE(input.count({out(0, i), out(1, i), out(2, i)}));
  std::vector<std::uint32_t> cube(out.cols());
  for (Eigen::Index i = 0; i < out.cols(); ++i) cube[i] = detail::cube_key(layout, out(0, i), out(1, i), out(2, i));
  int over = 0;
  for (Eigen::Index i = 0; i < out.cols(); ++i) {
    int neighbours = 0;
    std::set<std::uint32_t> neighbour_cubes;
    for (Eigen::Index j = 0; j < out.cols(); ++j) {
      if (i == j) continue;
      if (detail::sq_dist(out(0, i), out(1, i), out(2, i), out(0, j), out(1, j), out(2, j)) < layout.radius_sq) {
        ++neighbours;
        neighbour_cubes.insert(cube[j]);
      }
    }
    if (neighbours > config.max_neighbours) {
      ++over;
      // Over the bound: this must be an anchor whose neighbours are all anchors, i.e. one per other cube.
      EXPECT_EQ(neighbours, static_cast<int>(neighbour_cubes.size()) - int(neighbour_cubes.count(cube[i])))
          << "point " << i << " has " << neighbours << " neighbours";
      EXPECT_EQ(neighbour_cubes.count(cube[i]), 0u);
    }
  }
  if (config.max_neighbours >= 26) {
    EXPECT_EQ(over, 0);
  }
}

// The documented algorithm, literally and slowly (brute-force neighbour counts, one point at a time), as the
// reference that the optimized CPU code must match exactly, point for point and in the same order.
Eigen::Matrix3Xf reference_csnb(const Eigen::Matrix3Xf& in, const CsnbConfig& config) {
  const detail::CsnbLayout layout = detail::make_csnb_layout(detail::compute_bounds(in, 1), config);
  struct P {
    float x, y, z;
    std::uint32_t column, key;
    int c[3];
  };
  std::vector<P> pts;
  for (Eigen::Index i = 0; i < in.cols(); ++i) {
    const float x = in(0, i), y = in(1, i), z = in(2, i);
    if (!detail::finite3(x, y, z)) continue;
    pts.push_back({x, y, z, std::uint32_t(i), detail::cube_key(layout, x, y, z),
                   {int(detail::cube_axis(layout, x, 0)), int(detail::cube_axis(layout, y, 1)),
                    int(detail::cube_axis(layout, z, 2))}});
  }
  std::stable_sort(pts.begin(), pts.end(), [](const P& a, const P& b) { return a.key < b.key; });
  const std::size_t m = pts.size();
  std::vector<char> live(m, 1), settled(m, 0), anchor(m, 0);
  std::vector<std::uint32_t> anchors;
  for (std::size_t b = 0; b < m;) {
    std::size_t e = b, best = b;
    for (; e < m && pts[e].key == pts[b].key; ++e) {
      if (detail::centre_sq_dist(layout, pts[e].key, pts[e].x, pts[e].y, pts[e].z) <
          detail::centre_sq_dist(layout, pts[best].key, pts[best].x, pts[best].y, pts[best].z))
        best = e;
    }
    anchor[best] = 1;
    anchors.push_back(std::uint32_t(best));
    b = e;
  }
  auto near = [&](std::size_t s, std::size_t t) {
    for (int a = 0; a < 3; ++a)
      if (std::abs(pts[s].c[a] - pts[t].c[a]) > layout.reach) return false;
    return detail::sq_dist(pts[s].x, pts[s].y, pts[s].z, pts[t].x, pts[t].y, pts[t].z) < layout.radius_sq;
  };
  auto marked = [&](std::size_t s) {
    int k = 0;
    for (std::size_t t = 0; t < m; ++t) k += t != s && live[t] && near(s, t);
    return k > config.max_neighbours;
  };
  std::vector<std::uint64_t> order;
  for (std::size_t s = 0; s < m; ++s)
    if (!anchor[s]) order.push_back(detail::csnb_priority(config.seed, pts[s].column, std::uint32_t(s)));
  std::sort(order.begin(), order.end());
  const std::size_t K = std::size_t(config.batch_size);
  for (std::size_t cursor = 0;;) {
    std::vector<std::size_t> batch;
    std::size_t next = order.size();
    for (std::size_t i = cursor; i < order.size(); ++i) {
      const std::size_t s = std::uint32_t(order[i]);
      if (!live[s] || settled[s]) continue;
      if (!marked(s)) {
        settled[s] = 1;
        continue;
      }
      if (batch.size() == K) {
        next = i;
        break;
      }
      batch.push_back(s);
    }
    for (std::size_t s : batch) live[s] = 0;
    if (next == order.size()) break;
    cursor = next;
  }
  std::vector<std::uint32_t> claims;
  for (std::uint32_t a : anchors)
    if (marked(a)) claims.push_back(a);
  for (std::uint32_t a : claims)
    for (std::size_t t = 0; t < m; ++t)
      if (!anchor[t] && near(a, t)) live[t] = 0;
  Eigen::Matrix3Xf out(3, std::count(live.begin(), live.end(), 1));
  Eigen::Index o = 0;
  for (std::size_t s = 0; s < m; ++s)
    if (live[s]) out.col(o++) << pts[s].x, pts[s].y, pts[s].z;
  return out;
}

TEST(Csnb, EqualsTheLiteralAlgorithm) {
  const Eigen::Matrix3Xf corridor = bench::make_corridor_cloud(4, 96, 54);
  const Eigen::Matrix3Xf random = test::random_cloud(21, 2500, -0.3f, 0.4f);
  struct Case {
    const Eigen::Matrix3Xf* cloud;
    double voxel_m;
    int threshold, batch, exponent;
  };
  // Batches of 1 (a new batch at every mark, also inside a run of sure points) and one batch for everything.
  for (const Case& c : {Case{&random, 0.1, 4, 7, 0}, Case{&random, 0.05, 0, 1000, 0}, Case{&random, 0.08, 2, 3, 5},
                        Case{&random, 0.08, 2, 1, 0}, Case{&random, 0.1, 3, 1000000, 0},
                        Case{&corridor, 0.05, 4, 11, 0}, Case{&corridor, 0.1, 8, 200, 0},
                        Case{&corridor, 0.2, 3, 5, 4}}) {
    CsnbConfig config;
    config.voxel_size_m = c.voxel_m;
    config.max_neighbours = c.threshold;
    config.batch_size = c.batch;
    config.grid_exponent = c.exponent;
    config.seed = 7;
    const Eigen::Matrix3Xf expected = reference_csnb(*c.cloud, config);
    for (int threads : {1, 2, 3}) {
      const Eigen::Matrix3Xf got = csnb(*c.cloud, config, threads);
      ASSERT_EQ(got.cols(), expected.cols()) << "voxel " << c.voxel_m << " threads " << threads;
      EXPECT_TRUE(got == expected) << "voxel " << c.voxel_m << " threads " << threads;
    }
    EXPECT_LT(expected.cols(), c.cloud->cols());
  }
}

// The plain counting loops (CPUs without AVX2, or the switch off) give the same output as the AVX2 ones, on
// a cloud large enough for many windows of the walk, and the literal algorithm agrees on a smaller one.
TEST(Csnb, SameOutputWithoutSimd) {
  const Eigen::Matrix3Xf corridor = bench::make_corridor_cloud(2, 320, 180);
  for (double voxel : {0.02, 0.05}) {
    CsnbConfig config;
    config.voxel_size_m = voxel;
    config.batch_size = 200;
    const Eigen::Matrix3Xf simd = csnb(corridor, config, 2);
    test::WithoutSimd plain;
    const Eigen::Matrix3Xf out = csnb(corridor, config, 2);
    ASSERT_EQ(out.cols(), simd.cols()) << "voxel " << voxel;
    EXPECT_TRUE(out == simd) << "voxel " << voxel;
  }
  const Eigen::Matrix3Xf random = test::random_cloud(31, 3000, -0.3f, 0.4f);
  CsnbConfig config;
  config.voxel_size_m = 0.08;
  config.max_neighbours = 3;
  config.batch_size = 5;
  test::WithoutSimd plain;
  const Eigen::Matrix3Xf out = csnb(random, config, 2);
  const Eigen::Matrix3Xf expected = reference_csnb(random, config);
  ASSERT_EQ(out.cols(), expected.cols());
  EXPECT_TRUE(out == expected);
}

TEST(Csnb, DensityBoundAndNoCubeLostOnRandomClouds) {
  for (int threshold : {0, 2, 5, 26}) {
    CsnbConfig config;
    config.voxel_size_m = 0.1;
    config.max_neighbours = threshold;
    config.batch_size = 50;
    const Eigen::Matrix3Xf in = test::random_cloud(11 + threshold, 6000, -0.5f, 0.7f);
    const Eigen::Matrix3Xf out = csnb(in, config, 2);
    EXPECT_LT(out.cols(), in.cols());
    check_csnb(in, out, config);
  }
}

TEST(Csnb, DensityBoundOnCorridorPatch) {
  const Eigen::Matrix3Xf corridor = bench::make_corridor_cloud(3, 160, 90);
  CsnbConfig config;
  config.voxel_size_m = 0.05;
  config.max_neighbours = 3;
  config.batch_size = 100;
  const Eigen::Matrix3Xf out = csnb(corridor, config, 2);
  EXPECT_LT(out.cols(), corridor.cols() * 3 / 4);
  check_csnb(corridor, out, config);
}

TEST(Csnb, DeterministicForSeedAndThreads) {
  const Eigen::Matrix3Xf in = test::random_cloud(5, 20000, 0.f, 1.f);
  CsnbConfig config;
  config.voxel_size_m = 0.05;
  config.max_neighbours = 3;
  const Eigen::Matrix3Xf a = csnb(in, config, 1);
  const Eigen::Matrix3Xf b = csnb(in, config, 2);
  ASSERT_EQ(a.cols(), b.cols());
  EXPECT_TRUE(a == b);
  config.seed = 2;
  const Eigen::Matrix3Xf c = csnb(in, config, 2);
  EXPECT_FALSE(c.cols() == a.cols() && c == a);
}

TEST(Csnb, GridExponentAndSmallClouds) {
  const Eigen::Matrix3Xf in = test::random_cloud(9, 3000, 0.f, 0.3f);
  for (int n : {0, 4, 6, 9}) {
    CsnbConfig config;
    config.voxel_size_m = 0.05;
    config.grid_exponent = n;
    config.max_neighbours = 1;
    check_csnb(in, csnb(in, config), config);
  }
  const float nan = std::numeric_limits<float>::quiet_NaN();
  Eigen::Matrix3Xf odd(3, 3);
  odd << nan, 1.f, 1.f, 0.f, 2.f, 2.f, 0.f, 3.f, 3.f;
  CsnbConfig config;
  config.max_neighbours = 0;
  const Eigen::Matrix3Xf out = csnb(odd, config);
  ASSERT_EQ(out.cols(), 1);  // two identical points: one cube, one anchor
  EXPECT_EQ(csnb(Eigen::Matrix3Xf(3, 0), config).cols(), 0);
  // Tiny distance thresholds just keep distinct points.
  config.voxel_size_m = 1e-12;
  EXPECT_EQ(csnb(in, config).cols(), in.cols());
}

TEST(Csnb, BadConfigThrows) {
  const Eigen::Matrix3Xf in = test::random_cloud(1, 10, 0.f, 1.f);
  auto with = [](auto change) {
    CsnbConfig config;
    change(config);
    return config;
  };
  EXPECT_THROW(csnb(in, with([](CsnbConfig& c) { c.voxel_size_m = 0; })), std::invalid_argument);
  EXPECT_THROW(csnb(in, with([](CsnbConfig& c) { c.voxel_size_m = std::nan(""); })), std::invalid_argument);
  EXPECT_THROW(csnb(in, with([](CsnbConfig& c) { c.voxel_size_m = -1; })), std::invalid_argument);
  EXPECT_THROW(csnb(in, with([](CsnbConfig& c) { c.voxel_size_m = HUGE_VAL; })), std::invalid_argument);
  EXPECT_THROW(csnb(in, with([](CsnbConfig& c) { c.max_neighbours = -1; })), std::invalid_argument);
  EXPECT_THROW(csnb(in, with([](CsnbConfig& c) { c.batch_size = 0; })), std::invalid_argument);
  EXPECT_THROW(csnb(in, with([](CsnbConfig& c) { c.grid_exponent = 10; })), std::invalid_argument);
  EXPECT_THROW(csnb(in, with([](CsnbConfig& c) { c.grid_exponent = 3; })), std::invalid_argument);
}

}  // namespace
}  // namespace stvl::filter

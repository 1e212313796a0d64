#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <vector>

#include "bench/synthetic_corridor.hpp"
#include "filter/csnb.hpp"
#include "filter/detail/common.hpp"
#include "filter/reference/csnb.hpp"
#include "helpers.hpp"

namespace stvl::filter {
namespace {

std::set<std::array<int, 3>> occupied_cubes(const Eigen::Matrix3Xf& points, const reference::CsnbGrid& grid) {
  std::set<std::array<int, 3>> cubes;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    if (points.col(i).allFinite()) cubes.insert(grid.cube(points(0, i), points(1, i), points(2, i)));
  }
  return cubes;
}

// Checks the documented guarantee by brute force: every kept point has at most max_neighbours kept
// neighbours, except anchors, which may exceed it only through other anchors (one per cube); the output is
// a subset of the input and every occupied cube keeps a point.
void check_csnb(const Eigen::Matrix3Xf& in, const Eigen::Matrix3Xf& out, const CsnbConfig& config) {
  const reference::CsnbGrid grid = reference::csnb_grid(in, config);
  EXPECT_EQ(occupied_cubes(in, grid), occupied_cubes(out, grid));
  std::set<std::tuple<float, float, float>> input;
  for (Eigen::Index i = 0; i < in.cols(); ++i) input.insert({in(0, i), in(1, i), in(2, i)});
  for (Eigen::Index i = 0; i < out.cols(); ++i) ASSERT_TRUE(input.count({out(0, i), out(1, i), out(2, i)}));
  std::vector<std::array<int, 3>> cube(out.cols());
  for (Eigen::Index i = 0; i < out.cols(); ++i) cube[i] = grid.cube(out(0, i), out(1, i), out(2, i));
  int over = 0;
  for (Eigen::Index i = 0; i < out.cols(); ++i) {
    int neighbours = 0;
    std::set<std::array<int, 3>> neighbour_cubes;
    for (Eigen::Index j = 0; j < out.cols(); ++j) {
      if (i != j && grid.neighbours(out.col(i).data(), cube[i], out.col(j).data(), cube[j])) {
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

TEST(Csnb, EqualsTheLiteralAlgorithm) {
  const Eigen::Matrix3Xf corridor = bench::make_corridor_cloud(4, 96, 54);
  const Eigen::Matrix3Xf random = test::random_cloud(21, 2500, -0.3f, 0.4f);
  struct Case {
    const Eigen::Matrix3Xf* cloud;
    double voxel_m;
    int threshold, batch, exponent;
  };
  // Batches of 1 (a new batch at every mark, also inside a run of sure points) and one batch for everything.
  for (const Case& c :
       {Case{&random, 0.1, 4, 7, 0}, Case{&random, 0.05, 0, 1000, 0}, Case{&random, 0.08, 2, 3, 5},
        Case{&random, 0.08, 2, 1, 0}, Case{&random, 0.1, 3, 1000000, 0}, Case{&corridor, 0.05, 4, 11, 0},
        Case{&corridor, 0.1, 8, 200, 0}, Case{&corridor, 0.2, 3, 5, 4}}) {
    CsnbConfig config;
    config.voxel_size_m = c.voxel_m;
    config.max_neighbours = c.threshold;
    config.batch_size = c.batch;
    config.grid_exponent = c.exponent;
    config.seed = 7;
    const Eigen::Matrix3Xf expected = reference::csnb(*c.cloud, config);
    for (int threads : {1, 2, 3}) {
      EXPECT_TRUE(test::same_bits(csnb(*c.cloud, config, threads), expected))
          << "voxel " << c.voxel_m << " threads " << threads;
    }
    EXPECT_LT(expected.cols(), c.cloud->cols());
  }
}

// The reference's grid is the documented one; so is the optimized code's (detail::make_csnb_layout).
TEST(Csnb, GridAsDocumented) {
  Eigen::Matrix3Xf cloud(3, 3);
  cloud << -1.f, 0.5f, std::numeric_limits<float>::quiet_NaN(),  //
      2.f, 2.25f, 0.f,                                           //
      0.f, 0.125f, 0.f;
  CsnbConfig config;
  config.voxel_size_m = 0.125;
  reference::CsnbGrid grid = reference::csnb_grid(cloud, config);
  EXPECT_EQ(grid.extent_m, 1.5);
  EXPECT_EQ(grid.cube_edge_m, 0.125);
  EXPECT_EQ(grid.grid_exponent, 4);  // 12 cubes along x, at least 16 per axis
  EXPECT_EQ(grid.reach, 1);
  EXPECT_EQ(grid.cube(0.5f, 2.25f, 0.125f), (std::array<int, 3>{12, 2, 1}));
  EXPECT_EQ(grid.cube(-1.f, 2.f, 0.f), (std::array<int, 3>{0, 0, 0}));
  config.voxel_size_m = 0.001;  // 1500 cubes of d would be too many: extent / 512, n = 9
  grid = reference::csnb_grid(cloud, config);
  EXPECT_EQ(grid.cube_edge_m, 1.5 / 512);
  EXPECT_EQ(grid.grid_exponent, 9);
  EXPECT_EQ(grid.cube(0.5f, 2.25f, 0.125f)[0], 511);  // cube 512 clamped to the grid
  config.voxel_size_m = 0.125;
  config.grid_exponent = 5;  // given n: edge extent / 32, reach ceil(0.125 / edge) = 3
  grid = reference::csnb_grid(cloud, config);
  EXPECT_EQ(grid.cube_edge_m, 1.5 / 32);
  EXPECT_EQ(grid.reach, 3);
  EXPECT_EQ(grid.cube(0.5f, 2.25f, 0.125f), (std::array<int, 3>{31, 5, 2}));
  // The optimized code's layout on random clouds.
  test::Random r{77};
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Matrix3Xf in = test::mixed_cloud(r, r.range(1, 50), r.log_uniform(1e-3, 500.0), 0.01, 0.1, nullptr);
    CsnbConfig c;
    c.voxel_size_m = r.log_uniform(1e-4, 10.0);
    c.grid_exponent = r.pick({0, 0, 4, 7, 9});
    if (!test::any_finite(in)) continue;
    const reference::CsnbGrid expected = reference::csnb_grid(in, c);
    const detail::CsnbLayout layout = detail::make_csnb_layout(detail::compute_bounds(in, 1), c);
    ASSERT_EQ(layout.cube_edge_m, expected.cube_edge_m) << trial;
    ASSERT_EQ(layout.grid_exponent, expected.grid_exponent) << trial;
    ASSERT_EQ(layout.reach, expected.reach) << trial;
    ASSERT_EQ(layout.radius_sq, expected.radius_sq) << trial;
    for (int a = 0; a < 3; ++a) ASSERT_EQ(layout.min_m[a], expected.min_m[a]) << trial;
  }
}

// Random clouds of every shape, size and density the kernels branch on (sparse, sure and unsure points,
// batches of 1 to all, reach above 1, NaN/Inf, negative and far-off coordinates), on 1 to 3 threads with the
// SIMD paths on and off: bit for bit the literal algorithm's output. Sizes stay small enough for its
// quadratic cost; a few are large enough to split every step over 3 threads.
TEST(Csnb, EqualsTheLiteralAlgorithmOnRandomClouds) {
  test::Random r{4242};
  const Eigen::Index sizes[] = {0, 1, 2, 5, 40, 300, 1000, 2500, 6000};
  for (int trial = 0; trial < 64; ++trial) {
    const Eigen::Index n = trial % 16 == 15 ? 20000 : r.pick(sizes);
    const double size_m = r.log_uniform(0.1, 50.0);
    // Neighbours per point in a uniform cloud of n points: 4/3 pi d^3 n / size^3, from about 0.2 to 40; or,
    // one trial in four, d from the box alone, down to size / 3000 (cubes of extent / 512, larger than d).
    const double neighbours = r.log_uniform(0.2, 40.0);
    CsnbConfig config;
    config.voxel_size_m = size_m * std::cbrt(neighbours / (4.19 * double(std::max<Eigen::Index>(n, 1))));
    if (trial % 4 == 3) config.voxel_size_m = size_m / r.log_uniform(100.0, 3000.0);
    config.max_neighbours = r.range(0, 12);
    config.batch_size = std::max<int>(int(n / 400) + 1, r.pick({1, 2, 7, 50, 300, 1000, 1000000}));
    config.seed = r.bits();
    std::string what;
    const double lattice_m = config.voxel_size_m * r.pick({0.3, 0.5, 1.0});
    const Eigen::Matrix3Xf cloud = test::mixed_cloud(r, n, size_m, lattice_m, r.pick({0.0, 0.0, 0.002, 0.05}), &what);
    if (r.uniform() < 0.3 && test::any_finite(cloud)) {  // a given n, while reach stays small
      const int exponent = r.range(4, 9);
      config.grid_exponent = exponent;
      if (reference::csnb_grid(cloud, config).reach > 4) config.grid_exponent = 0;
    }
    const Eigen::Matrix3Xf expected = reference::csnb(cloud, config);
    for (const bool simd : {true, false}) {
      const test::SimdSetting setting(simd);
      for (int threads : {1, 2, 3}) {
        EXPECT_TRUE(test::same_bits(csnb(cloud, config, threads), expected))
            << "trial " << trial << ": " << what << ", voxel " << config.voxel_size_m << " m, max neighbours "
            << config.max_neighbours << ", batch " << config.batch_size << ", n " << config.grid_exponent << ", seed "
            << config.seed << ", threads " << threads << ", simd " << simd;
      }
    }
  }
}

// Points on lattices of step d / 2 or d from origins on them, with duplicates: exact coordinates on cube
// boundaries (where the floor of a quotient must not round), neighbours at exactly d (not neighbours), anchors
// at equal distances from their cube's centre. All finite (the vectorised cube keys) or with a NaN.
TEST(Csnb, EqualsTheLiteralAlgorithmOnLattices) {
  test::Random r{99};
  for (int trial = 0; trial < 24; ++trial) {
    CsnbConfig config;
    config.voxel_size_m = r.pick({0.125, 0.25});
    config.max_neighbours = r.range(0, 6);
    config.batch_size = r.pick({1, 5, 1000});
    config.seed = r.bits();
    const double step = config.voxel_size_m * r.pick({0.5, 1.0});
    const int side = r.range(4, 12);
    const double origin[3] = {step * r.range(-40, 40), step * r.range(-40, 40), step * r.range(-40, 40)};
    std::vector<Eigen::Vector3f> points;
    for (int i = 0; i < side * side * side; ++i) {
      const int copies = r.range(-1, 3);  // a quarter of the sites empty
      for (int c = 0; c < copies; ++c) {
        points.push_back(Eigen::Vector3d(origin[0] + step * (i % side), origin[1] + step * (i / side % side),
                                         origin[2] + step * (i / side / side))
                             .cast<float>());
      }
    }
    if (trial % 3 == 2) points.push_back(Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
    Eigen::Matrix3Xf cloud(3, static_cast<Eigen::Index>(points.size()));
    for (std::size_t i = 0; i < points.size(); ++i) cloud.col(static_cast<Eigen::Index>(i)) = points[i];
    const Eigen::Matrix3Xf expected = reference::csnb(cloud, config);
    for (const bool simd : {true, false}) {
      const test::SimdSetting setting(simd);
      for (int threads : {1, 3}) {
        EXPECT_TRUE(test::same_bits(csnb(cloud, config, threads), expected))
            << "trial " << trial << ": " << cloud.cols() << " points, step " << step << ", voxel "
            << config.voxel_size_m << ", max neighbours " << config.max_neighbours << ", batch " << config.batch_size
            << ", threads " << threads << ", simd " << simd;
      }
    }
  }
}

// The plain counting loops (CPUs without AVX2, or the switch off) give the same output as the AVX2 ones, on
// a cloud large enough for many windows of the walk.
TEST(Csnb, SameOutputWithoutSimd) {
  if (!detail::cpu_has_avx2()) GTEST_SKIP() << "no AVX2: the plain counting loops are the only ones";
  const Eigen::Matrix3Xf corridor = bench::make_corridor_cloud(2, 320, 180);
  for (double voxel : {0.02, 0.05}) {
    CsnbConfig config;
    config.voxel_size_m = voxel;
    config.batch_size = 200;
    const Eigen::Matrix3Xf simd = csnb(corridor, config, 2);
    test::WithoutSimd plain;
    EXPECT_TRUE(test::same_bits(csnb(corridor, config, 2), simd)) << "voxel " << voxel;
  }
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

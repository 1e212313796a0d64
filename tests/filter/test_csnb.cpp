#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>

#include "filter/cloud_io.hpp"
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
  const Eigen::Matrix3Xf corridor = make_corridor_cloud(3, 160, 90);
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

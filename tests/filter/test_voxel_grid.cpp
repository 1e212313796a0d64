#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "filter/passthrough.hpp"
#include "filter/reference/voxel_grid.hpp"
#include "filter/voxel_grid.hpp"
#include "helpers.hpp"

namespace stvl::filter {
namespace {

TEST(VoxelGrid, MatchesReferenceOnRandomClouds) {
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const Eigen::Matrix3Xf cloud = test::random_cloud(seed, 20000, -3.f, 2.f);
    for (double voxel : {0.05, 0.2, 1.0}) {
      for (int threads : {1, 2, 3}) {
        EXPECT_TRUE(test::same_bits(voxel_grid(cloud, {voxel, 1}, threads), reference::voxel_grid(cloud, {voxel, 1})))
            << "voxel " << voxel << " threads " << threads;
      }
    }
  }
}

// Random clouds of every shape, size and density the kernels branch on (32- and 64-bit keys, buckets split
// again or sorted by insertion, dense and sparse tables, NaN/Inf, negative and far-off coordinates), on 1 to
// 3 threads with the SIMD paths on and off: bit for bit the reference's output.
TEST(VoxelGrid, EqualsTheReferenceOnRandomClouds) {
  test::Random r{2024};
  const Eigen::Index sizes[] = {0, 1, 2, 3, 17, 100, 1000, 4000, 9000, 30000, 70000};
  for (int trial = 0; trial < 90; ++trial) {
    const Eigen::Index n = r.pick(sizes);
    const double size_m = r.log_uniform(0.05, 200.0);
    const bool tiny_voxels = trial % 10 == 0;  // 64-bit keys
    const double voxel_m = size_m / r.log_uniform(1.0, tiny_voxels ? 3e5 : 2000.0);
    const double lattice_m = voxel_m * r.pick({0.25, 0.5, 1.0, 3.0});
    std::string what;
    const Eigen::Matrix3Xf cloud = test::mixed_cloud(r, n, size_m, lattice_m, r.pick({0.0, 0.0, 0.001, 0.1}), &what);
    const VoxelGridConfig config{voxel_m, tiny_voxels ? 1 : r.pick({0, 1, 1, 2, 3, 6})};
    const Eigen::Matrix3Xf expected = reference::voxel_grid(cloud, config);
    for (const bool simd : {true, false}) {
      const test::SimdSetting setting(simd);
      for (int threads : {1, 2, 3}) {
        EXPECT_TRUE(test::same_bits(voxel_grid(cloud, config, threads), expected))
            << "trial " << trial << ": " << what << ", voxel " << voxel_m << " m, min points "
            << config.min_points_per_voxel << ", threads " << threads << ", simd " << simd;
      }
    }
  }
}

// The plain key loop (CPUs without AVX2, or the switch off) gives the same output as the AVX2 one.
TEST(VoxelGrid, SameOutputWithoutSimd) {
  if (!detail::cpu_has_avx2()) GTEST_SKIP() << "no AVX2: the plain key loop is the only one";
  const Eigen::Matrix3Xf cloud = test::random_cloud(8, 50000, -3.f, 2.f);
  for (double voxel : {0.02, 0.1}) {
    const Eigen::Matrix3Xf simd = voxel_grid(cloud, {voxel, 1}, 2);
    test::WithoutSimd plain;
    const Eigen::Matrix3Xf out = voxel_grid(cloud, {voxel, 1}, 2);
    ASSERT_EQ(out.cols(), simd.cols());
    EXPECT_TRUE(out == simd) << "voxel " << voxel;
    EXPECT_TRUE(test::same_bits(out, reference::voxel_grid(cloud, {voxel, 1})));
  }
}

TEST(VoxelGrid, MatchesReferenceOnBoundariesAndNegativeCoordinates) {
  Eigen::Matrix3Xf cloud(3, 0);
  for (int i = -20; i <= 20; ++i) {
    for (int j = -3; j <= 3; ++j) {
      cloud.conservativeResize(3, cloud.cols() + 1);
      cloud.col(cloud.cols() - 1) << 0.25f * i, 0.5f * j, -0.25f * (i % 3);
    }
  }
  // With a NaN point added, the keys come from the per-point path instead of the 32-bit branch-free one.
  Eigen::Matrix3Xf with_nan = cloud;
  with_nan.conservativeResize(3, cloud.cols() + 1);
  with_nan.col(cloud.cols()).setConstant(std::numeric_limits<float>::quiet_NaN());
  for (double voxel : {0.25, 0.5, 0.1, 0.05, 0.02}) {
    const Eigen::Matrix3Xf out = voxel_grid(cloud, {voxel, 1}, 2);
    EXPECT_TRUE(test::same_bits(out, reference::voxel_grid(cloud, {voxel, 1})));
    const Eigen::Matrix3Xf same = voxel_grid(with_nan, {voxel, 1}, 2);
    ASSERT_EQ(same.cols(), out.cols());
    EXPECT_TRUE((same.array() == out.array()).all()) << "voxel " << voxel;
  }
  // A point exactly on a boundary belongs to the voxel above it.
  Eigen::Matrix3Xf two(3, 2);
  two << -0.5f, -0.25f, 0.f, 0.f, 0.f, 0.f;
  EXPECT_EQ(voxel_grid(two, {0.25, 1}).cols(), 2);
  EXPECT_EQ(voxel_grid(two, {0.5, 1}).cols(), 1);
  EXPECT_EQ(voxel_grid(two, {1.0, 1}).cols(), 1);
}

TEST(VoxelGrid, MatchesReferenceWhenOneSliceHoldsMostPoints) {
  // A floor: most points share the key's high bits (one z slice), so their bucket is split again before it
  // is sorted; the rest are spread over the room. NaNs in between keep the index bookkeeping honest.
  Eigen::Matrix3Xf cloud = test::random_cloud(11, 90000, 0.f, 4.f);
  for (Eigen::Index i = 0; i < cloud.cols(); ++i) {
    if (i % 4 != 0) cloud(2, i) = 0.001f * float(i % 7);
    if (i % 1001 == 0) cloud(1, i) = std::numeric_limits<float>::quiet_NaN();
  }
  for (double voxel : {0.01, 0.02, 0.1}) {
    for (int threads : {1, 2}) {
      EXPECT_TRUE(test::same_bits(voxel_grid(cloud, {voxel, 2}, threads), reference::voxel_grid(cloud, {voxel, 2})))
          << "voxel " << voxel << " threads " << threads;
    }
  }
}

TEST(VoxelGrid, BucketHoldingEveryKeyOfItsTable) {
  // 1 m voxels, 1024 along x and 256 along z: 18-bit keys, so a bucket (one z layer) is summed in a table of
  // its 10 low bits. The z = 0 layer holds every one of its 1024 keys twice: the second round of points comes
  // after all slots are in use.
  Eigen::Matrix3Xf cloud(3, 2 * 1024 + 2);
  for (int round = 0; round < 2; ++round) {
    for (int x = 0; x < 1024; ++x) cloud.col(round * 1024 + x) << x + 0.25f + 0.5f * round, 0.5f, 0.5f;
  }
  cloud.col(2048) << 0.5f, 0.5f, 255.5f;
  cloud.col(2049) << 1023.5f, 0.5f, 100.5f;
  for (int threads : {1, 2}) {
    const Eigen::Matrix3Xf out = voxel_grid(cloud, {1.0, 1}, threads);
    ASSERT_EQ(out.cols(), 1026);
    EXPECT_TRUE(test::same_bits(out, reference::voxel_grid(cloud, {1.0, 1})));
    EXPECT_FLOAT_EQ(out(0, 7), 7.5f);  // the mean of 7.25 and 7.75
  }
}

TEST(VoxelGrid, MinPointsPerVoxel) {
  const Eigen::Matrix3Xf cloud = test::random_cloud(7, 5000, 0.f, 1.f);
  for (int min_points : {0, 1, 2, 5, 40}) {
    const VoxelGridConfig config{0.1, min_points};
    EXPECT_TRUE(test::same_bits(voxel_grid(cloud, config, 2), reference::voxel_grid(cloud, config))) << min_points;
  }
  EXPECT_EQ(voxel_grid(cloud, {0.1, 100000}).cols(), 0);
  EXPECT_THROW(voxel_grid(cloud, {0.1, -1}), std::invalid_argument);
}

TEST(VoxelGrid, NonFiniteEmptyAndSinglePoints) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  Eigen::Matrix3Xf cloud(3, 5);
  cloud << 0.01f, nan, 0.02f, inf, 5.f,  //
      0.01f, 0.f, 0.02f, 0.f, 5.f,       //
      0.01f, 0.f, 0.02f, 0.f, -inf;
  const Eigen::Matrix3Xf out = voxel_grid(cloud, {0.1, 1});
  ASSERT_EQ(out.cols(), 1);
  EXPECT_NEAR(out(0, 0), 0.015f, 1e-6);
  EXPECT_EQ(voxel_grid(Eigen::Matrix3Xf(3, 0), {0.1, 1}).cols(), 0);
  Eigen::Matrix3Xf all_nan = Eigen::Matrix3Xf::Constant(3, 4, nan);
  EXPECT_EQ(voxel_grid(all_nan, {0.1, 1}).cols(), 0);
  Eigen::Matrix3Xf one(3, 1);
  one << -1.5f, 2.5f, 1e6f;
  const Eigen::Matrix3Xf single = voxel_grid(one, {1e-12, 1});
  ASSERT_EQ(single.cols(), 1);
  EXPECT_EQ(single.col(0), one.col(0));
}

TEST(VoxelGrid, AbsurdVoxelSizesThrow) {
  const Eigen::Matrix3Xf cloud = test::random_cloud(3, 100, 0.f, 1.f);
  for (double voxel : {0.0, -0.1, std::nan(""), std::numeric_limits<double>::infinity(), -1e300}) {
    EXPECT_THROW(voxel_grid(cloud, {voxel, 1}), std::invalid_argument) << voxel;
  }
  // 1 m cube at 1e-12 m needs 1e36 voxels: a clear error, never garbage.
  try {
    voxel_grid(cloud, {1e-12, 1});
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("64-bit key"), std::string::npos) << e.what();
  }
}

TEST(VoxelGrid, HugeExtentWithTinyVoxels) {
  // 1e5 m along x at 1 mm: 1e8 voxels per axis (27 bits, beyond 21 bits per axis) but the box fits 64 bits.
  Eigen::Matrix3Xf line(3, 4);
  line << -5e4f, -5e4f, 0.f, 5e4f,  //
      0.f, 0.0004f, 0.f, 0.f,       //
      0.f, 0.f, 0.f, 0.f;
  const Eigen::Matrix3Xf out = voxel_grid(line, {0.001, 1});
  EXPECT_TRUE(test::same_bits(out, reference::voxel_grid(line, {0.001, 1})));
  EXPECT_EQ(out.cols(), 3);
  // 1e5 m in every axis at 1 mm needs 1e24 voxels: clear error.
  Eigen::Matrix3Xf cube(3, 2);
  cube << -5e4f, 5e4f, -5e4f, 5e4f, -5e4f, 5e4f;
  EXPECT_THROW(voxel_grid(cube, {0.001, 1}), std::invalid_argument);
}

TEST(VoxelGrid, TenMillionPoints) {
  const Eigen::Index n = 10'000'000;
  Eigen::Matrix3Xf cloud(3, n);
  // Exact binary coordinates: steps of 1/128 m, voxels of 1/16 m hold 8 steps per axis.
  for (Eigen::Index i = 0; i < n; ++i) {
    cloud.col(i) << float(i % 1000) / 128.f, float((i / 1000) % 100) / 128.f, float(i / 100000) / 128.f;
  }
  const Eigen::Matrix3Xf out = voxel_grid(cloud, {1.0 / 16.0, 1}, 2);
  ASSERT_EQ(out.cols(), 125 * 13 * 13);
  EXPECT_FLOAT_EQ(out(0, 0), 3.5f / 128.f);
  EXPECT_FLOAT_EQ(out(2, 0), 3.5f / 128.f);
  // Last voxel: x steps 992..999, y and z steps 96..99.
  EXPECT_FLOAT_EQ(out(0, out.cols() - 1), 995.5f / 128.f);
  EXPECT_FLOAT_EQ(out(1, out.cols() - 1), 97.5f / 128.f);
}

TEST(Passthrough, KeepsClosedRangeAndDropsNonFinite) {
  Eigen::Matrix3Xf cloud(3, 5);
  cloud << 0, 1, 2, 3, std::numeric_limits<float>::quiet_NaN(),  //
      0, 0, 0, 0, 0,                                             //
      -0.5f, 0.0f, 1.0f, 2.5f, 1.0f;
  const Eigen::Matrix3Xf out = passthrough(cloud, {0.0, 1.0});
  ASSERT_EQ(out.cols(), 2);
  EXPECT_EQ(out(0, 0), 1.f);
  EXPECT_EQ(out(0, 1), 2.f);
  EXPECT_EQ(passthrough(cloud, {}).cols(), 4);
  EXPECT_THROW(passthrough(cloud, {2.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(passthrough(cloud, {std::nan(""), 1.0}), std::invalid_argument);
}

}  // namespace
}  // namespace stvl::filter

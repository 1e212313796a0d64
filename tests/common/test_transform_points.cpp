// transform_points (common/transform_points.hpp) against the Eigen expression it stands in for, bit for bit: small
// clouds (Eigen's coefficient-wise product), large ones in blocks of the pipeline's size and odd sizes (its
// blocked product with remainders), wide coordinates and a rotation with no zero entry.
#include "common/transform_points.hpp"

#include <gtest/gtest.h>

#include <random>

#include <Eigen/Geometry>

namespace stvl {
namespace {

TEST(TransformPoints, RoundsAsEigensProduct) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> coord(-40.0f, 40.0f), angle(-3.0f, 3.0f);
  std::size_t compared = 0, moved = 0;
  for (const Eigen::Index n : {1, 2, 3, 5, 7, 16, 31, 100, 4097, 16384, 16385, 50001}) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(angle(rng), Eigen::Vector3d(angle(rng), angle(rng), 1.0).normalized()).matrix();
    T.translation() = Eigen::Vector3d(coord(rng), coord(rng), 0.1 * coord(rng));
    const Eigen::Matrix3f R = T.linear().cast<float>();
    const Eigen::Vector3f t = T.translation().cast<float>();
    Eigen::Matrix3Xf points(3, n);
    for (Eigen::Index j = 0; j < n; ++j) points.col(j) << coord(rng), coord(rng), 0.05f * coord(rng);
    Eigen::Matrix3Xf eigen(3, n), ours(3, n);
    for (Eigen::Index b = 0; b < n; b += 16384) {  // the blocks pipeline/sensing.cpp took them in
      const Eigen::Index m = std::min<Eigen::Index>(16384, n - b);
      eigen.middleCols(b, m) = (R * points.middleCols(b, m)).colwise() + t;
    }
    transform_points(R, t, points.data(), ours.data(), std::size_t(n));
    for (Eigen::Index j = 0; j < n; ++j)
      for (int i = 0; i < 3; ++i) {
        ASSERT_EQ(ours(i, j), eigen(i, j)) << "n " << n << " point " << j << " axis " << i;
        ++compared;
        // A plain left-to-right sum rounds differently for many points: the order is what this checks.
        moved += ((R(i, 0) * points(0, j) + R(i, 1) * points(1, j)) + R(i, 2) * points(2, j)) + t[i] != ours(i, j);
      }
  }
  EXPECT_GT(compared, 200000u);
  EXPECT_GT(moved, compared / 20) << "the left-to-right sum should differ somewhere";
}

}  // namespace
}  // namespace stvl

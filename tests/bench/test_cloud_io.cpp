#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>

#include "bench/cloud_io.hpp"
#include "bench/synthetic_corridor.hpp"

namespace stvl::bench {
namespace {

TEST(CloudIo, RoundTripAndBadFiles) {
  const std::string path = ::testing::TempDir() + "stvl_bench_cloud.stvlcld";
  const Eigen::Matrix3Xf cloud = make_corridor_cloud(8, 48, 27);
  ASSERT_GT(cloud.cols(), 1000);
  save_cloud(path, cloud);
  EXPECT_TRUE(load_cloud(path) == cloud);
  {
    std::ofstream out(path, std::ios::binary | std::ios::app);
    out.put('x');
  }
  EXPECT_THROW(load_cloud(path), std::invalid_argument);
  {
    std::ofstream out(path, std::ios::binary);
    out << "NOTACLOUDFILE...";
  }
  EXPECT_THROW(load_cloud(path), std::invalid_argument);
  EXPECT_THROW(load_cloud(path + ".missing"), std::runtime_error);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace stvl::bench

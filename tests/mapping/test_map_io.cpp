#include <gtest/gtest.h>

#include <unistd.h>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include "mapping/voxel_map.hpp"
#include "test_helpers.hpp"

namespace stvl::mapping {
namespace {

VoxelMap sample_map() {
  StvlConfig config;
  config.voxel_size_m = 0.1;
  config.voxel_decay_s = 7.5;
  config.decay_model = DecayModel::kExponential;
  config.mark_threshold = 3;
  VoxelMap map(config);
  map.set_voxels({{{-3, 4, 0}, 1.25}, {{0, 0, 0}, 2.5}, {{100, -200, 7}, 3.75}, {{-1, -1, -1}, 0.5}});
  return map;
}

TEST(MapIo, VdbRoundTripKeepsKeysTimesAndConfig) {
  const VoxelMap map = sample_map();
  const std::string path = ::testing::TempDir() + "stvl_map_test.vdb";
  map.save_vdb(path);
  const VoxelMap loaded = VoxelMap::load_vdb(path);
  EXPECT_TRUE(test::same_voxels(map.voxels(), loaded.voxels()));
  EXPECT_EQ(loaded.config().voxel_size_m, 0.1);
  EXPECT_EQ(loaded.config().voxel_decay_s, 7.5);
  EXPECT_EQ(loaded.config().decay_model, DecayModel::kExponential);
  EXPECT_EQ(loaded.config().mark_threshold, 3);
  EXPECT_EQ(loaded.lookup({-0.25, 0.45, 0.05}), 1.25);
  // The loaded map keeps the time order: earlier times are rejected.
  VoxelMap reloaded = VoxelMap::load_vdb(path);
  EXPECT_THROW(reloaded.clear({}, 3.0), std::invalid_argument);
  EXPECT_NO_THROW(reloaded.clear({}, 4.0));
}

TEST(MapIo, VdbPrintReadsTheFile) {
  if (access("/usr/bin/vdb_print", X_OK) != 0) GTEST_SKIP() << "vdb_print not installed";
  const std::string path = ::testing::TempDir() + "stvl_map_print.vdb";
  sample_map().save_vdb(path);
  const std::string out = path + ".txt";
  ASSERT_EQ(std::system(("/usr/bin/vdb_print -l '" + path + "' > '" + out + "' 2>&1").c_str()), 0);
  std::ifstream in(out);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("stvl_voxels"), std::string::npos) << text.str();
  EXPECT_NE(text.str().find("voxel_size"), std::string::npos) << text.str();
}

TEST(MapIo, LoadRejectsMissingOrForeignFiles) {
  EXPECT_THROW(VoxelMap::load_vdb("/nonexistent/stvl.vdb"), std::runtime_error);
  const std::string junk = ::testing::TempDir() + "stvl_junk.vdb";
  std::ofstream(junk) << "not a vdb file";
  EXPECT_THROW(VoxelMap::load_vdb(junk), std::runtime_error);
}

TEST(MapIo, PlyParsesToVoxelCentres) {
  const VoxelMap map = sample_map();
  const std::string path = ::testing::TempDir() + "stvl_map_test.ply";
  map.save_ply(path);
  std::ifstream in(path, std::ios::binary);
  std::string line;
  std::size_t vertices = 0;
  std::vector<std::string> properties;
  std::getline(in, line);
  ASSERT_EQ(line, "ply");
  std::getline(in, line);
  ASSERT_EQ(line, "format binary_little_endian 1.0");
  while (std::getline(in, line) && line != "end_header") {
    if (line.rfind("element vertex ", 0) == 0) vertices = std::stoul(line.substr(15));
    if (line.rfind("property ", 0) == 0) properties.push_back(line);
  }
  ASSERT_EQ(vertices, map.size());
  ASSERT_EQ(properties.size(), 4u);
  EXPECT_EQ(properties[3], "property double time");
  const Eigen::Matrix3Xf centres = map.voxel_centers();
  const auto voxels = map.voxels();
  for (std::size_t i = 0; i < vertices; ++i) {
    float xyz[3];
    double time = 0.0;
    in.read(reinterpret_cast<char*>(xyz), sizeof(xyz));
    in.read(reinterpret_cast<char*>(&time), sizeof(time));
    ASSERT_TRUE(in.good());
    EXPECT_TRUE(Eigen::Vector3f(xyz[0], xyz[1], xyz[2]).isApprox(centres.col(static_cast<Eigen::Index>(i))));
    EXPECT_EQ(time, voxels[i].time_s);
  }
  EXPECT_EQ(in.peek(), std::char_traits<char>::eof());
}

}  // namespace
}  // namespace stvl::mapping

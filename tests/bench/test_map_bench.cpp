#include <gtest/gtest.h>

#include <sstream>
#include <stdexcept>
#include <string>

#include "bench/map_bench.hpp"
#include "bench/octomap_peer.hpp"

namespace stvl::bench {
namespace {

TEST(MapBench, RowsPerSizeAndTable) {
  MapBenchOptions options;
  options.frames = 3;
  options.sizes = {100, 20000};
  options.threads = 1;
  const MapBenchResult result = run_map_bench(options);
  ASSERT_EQ(result.rows.size(), 2u);
  EXPECT_GT(result.points_per_frame, 1000.0);
  EXPECT_EQ(result.have_octomap, OctomapPeer::available());
  for (const MapBenchRow& row : result.rows) {
    EXPECT_TRUE(row.full_walk_matches) << row.prefilled_voxels;
    EXPECT_GT(row.final_voxels, row.prefilled_voxels);
    EXPECT_GT(row.mark_ms, 0.0);
    EXPECT_EQ(row.octomap_insert_ms > 0.0, result.have_octomap);
  }
  std::ostringstream table;
  print_map_bench(result, table);
  EXPECT_NE(table.str().find("| 20000 |"), std::string::npos) << table.str();

  options.octomap = false;
  options.sizes = {100};
  EXPECT_FALSE(run_map_bench(options).have_octomap);
  options.frames = 0;
  EXPECT_THROW(run_map_bench(options), std::invalid_argument);
}

}  // namespace
}  // namespace stvl::bench

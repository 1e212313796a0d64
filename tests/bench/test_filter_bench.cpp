#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "bench/filter_bench.hpp"
#include "bench/synthetic_corridor.hpp"

namespace stvl::bench {
namespace {

TEST(FilterBench, RowsAndTable) {
  FilterBenchConfig config;
  config.warmup = 0;
  config.repetitions = 1;
  config.cuda = false;
  config.voxel_sizes_m = {0.2};  // the small cloud is sparse
  const auto rows = run_filter_bench({{"small", make_corridor_cloud(1, 64, 36)}}, config);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].method, "voxel/cpu");
  EXPECT_EQ(rows[1].method, "csnb/cpu");
  EXPECT_EQ(rows[0].points_in, rows[1].points_in);
  EXPECT_LT(rows[0].points_out, rows[0].points_in);
  std::ostringstream table;
  print_filter_bench_table(table, rows);
  EXPECT_NE(table.str().find("| small | csnb/cpu |"), std::string::npos) << table.str();
  EXPECT_NE(table.str().find("| 1.00 |"), std::string::npos) << table.str();  // the baseline against itself
}

}  // namespace
}  // namespace stvl::bench

#pragma once
// The filter benchmark's core: every filter on every cloud at every voxel size, on the CPU and, where a GPU is
// usable, on CUDA in each memory mode. Wall time per call (transfers included), after warm-up. Needs Eigen and
// stvl_filter only, so filter-bench-standalone builds with filter/ alone.
#include <Eigen/Core>

#include <cstddef>
#include <iosfwd>
#include <string>
#include <vector>

#include "filter/filter.hpp"

namespace stvl::bench {

struct BenchmarkCloud {
  std::string name;
  Eigen::Matrix3Xf points;
};

struct FilterBenchConfig {
  std::vector<double> voxel_sizes_m{0.02};
  std::vector<filter::FilterType> filters{filter::FilterType::kVoxel, filter::FilterType::kCsnb};
  bool cpu = true;
  bool cuda = true;  // skipped (no rows) when no GPU is usable
  std::vector<filter::MemoryMode> memory_modes{filter::MemoryMode::kCopy, filter::MemoryMode::kPinned,
                                               filter::MemoryMode::kMapped, filter::MemoryMode::kManaged};
  int cpu_threads = 0;
  int warmup = 3;
  int repetitions = 20;
  filter::CsnbConfig csnb;  // voxel_size_m is replaced by each of voxel_sizes_m
};

struct FilterBenchRow {
  std::string cloud;
  std::string method;  // e.g. "voxel/cpu", "csnb/cuda/pinned", or a peer's name such as "pcl2/cpu"
  double voxel_size_m = 0.0;
  std::size_t points_in = 0;
  std::size_t points_out = 0;
  double mean_ms = 0.0;
  double std_ms = 0.0;
};

std::vector<FilterBenchRow> run_filter_bench(const std::vector<BenchmarkCloud>& clouds,
                                             const FilterBenchConfig& config);

// Markdown table; "x baseline" is the baseline row's mean / this row's mean, the baseline being the row
// with method == baseline_method for the same cloud and voxel size (blank when there is none).
void print_filter_bench_table(std::ostream& out, const std::vector<FilterBenchRow>& rows,
                              const std::string& baseline_method = "voxel/cpu");

}  // namespace stvl::bench

#pragma once
// Benchmark core: every filter on every cloud at every voxel size, on the CPU and, where a GPU is usable,
// on CUDA in each memory mode. Wall time per call (transfers included), after warm-up.
#include <Eigen/Core>

#include <iosfwd>
#include <string>
#include <vector>

#include "filter/filter.hpp"

namespace stvl::filter {

struct BenchmarkCloud {
  std::string name;
  Eigen::Matrix3Xf points;
};

struct BenchmarkConfig {
  std::vector<double> voxel_sizes_m{0.02};
  std::vector<FilterType> filters{FilterType::kVoxel, FilterType::kCsnb};
  bool cpu = true;
  bool cuda = true;  // skipped (no rows) when no GPU is usable
  std::vector<MemoryMode> memory_modes{MemoryMode::kCopy, MemoryMode::kPinned, MemoryMode::kMapped,
                                       MemoryMode::kManaged};
  int cpu_threads = 0;
  int warmup = 3;
  int repetitions = 20;
  CsnbConfig csnb;  // voxel_size_m is replaced by each of voxel_sizes_m
};

struct BenchmarkRow {
  std::string cloud;
  std::string method;  // e.g. "voxel/cpu", "csnb/cuda/pinned", or a peer's name such as "pcl/cpu"
  double voxel_size_m = 0.0;
  std::size_t points_in = 0;
  std::size_t points_out = 0;
  double mean_ms = 0.0;
  double std_ms = 0.0;
};

std::vector<BenchmarkRow> run_benchmark(const std::vector<BenchmarkCloud>& clouds, const BenchmarkConfig& config);

// Times fn() `repetitions` times after `warmup` calls; returns {mean, std} in ms.
template <class Fn>
std::pair<double, double> time_ms(Fn&& fn, int warmup, int repetitions);

// Markdown table; "x baseline" is the baseline row's mean / this row's mean, the baseline being the row
// with method == baseline_method for the same cloud and voxel size (blank when there is none).
void print_benchmark_table(std::ostream& out, const std::vector<BenchmarkRow>& rows,
                           const std::string& baseline_method = "voxel/cpu");

}  // namespace stvl::filter

#include "filter/benchmark_impl.hpp"

#include "bench/filter_bench.hpp"

#include <cstdio>
#include <ostream>

#include "bench/timing.hpp"

namespace stvl::bench {

using filter::Device;
using filter::FilterType;
using filter::MemoryMode;

std::vector<FilterBenchRow> run_filter_bench(const std::vector<BenchmarkCloud>& clouds,
                                             const FilterBenchConfig& config) {
  std::vector<FilterBenchRow> rows;
  struct Variant {
    Device device;
    MemoryMode memory;
    std::string label;
  };
  std::vector<Variant> variants;
  if (config.cpu) variants.push_back({Device::kCpu, MemoryMode::kCopy, "cpu"});
  if (config.cuda && filter::cuda_available()) {
    for (MemoryMode mode : config.memory_modes)
      variants.push_back({Device::kCuda, mode, std::string("cuda/") + to_string(mode)});
  }
  for (const BenchmarkCloud& cloud : clouds) {
    for (double voxel_size_m : config.voxel_sizes_m) {
      for (FilterType type : config.filters) {
        for (const Variant& variant : variants) {
          filter::FilterConfig fc;
          fc.type = type;
          fc.device = variant.device;
          fc.memory = variant.memory;
          fc.passthrough_enabled = false;
          fc.cpu_threads = config.cpu_threads;
          fc.voxel.voxel_size_m = voxel_size_m;
          fc.csnb = config.csnb;
          fc.csnb.voxel_size_m = voxel_size_m;
          filter::Filter under_test(fc);
          std::size_t out_points = 0;
          const auto [mean, sd] =
              time_ms([&] { out_points = static_cast<std::size_t>(under_test.apply(cloud.points).cols()); },
                      config.warmup, config.repetitions);
          rows.push_back({cloud.name, std::string(to_string(type)) + "/" + variant.label, voxel_size_m,
                          static_cast<std::size_t>(cloud.points.cols()), out_points, mean, sd});
        }
      }
    }
  }
  return rows;
}

void print_filter_bench_table(std::ostream& out, const std::vector<FilterBenchRow>& rows,
                              const std::string& baseline_method) {
  out << "| cloud | method | voxel m | points in | points out | mean ms | std ms | x " << baseline_method << " |\n"
      << "|---|---|---:|---:|---:|---:|---:|---:|\n";
  char line[512];
  for (const FilterBenchRow& row : rows) {
    const FilterBenchRow* base = nullptr;
    for (const FilterBenchRow& b : rows) {
      if (b.method == baseline_method && b.cloud == row.cloud && b.voxel_size_m == row.voxel_size_m) base = &b;
    }
    char ratio[32] = "";
    if (base && row.mean_ms > 0.0) std::snprintf(ratio, sizeof(ratio), "%.2f", base->mean_ms / row.mean_ms);
    std::snprintf(line, sizeof(line), "| %s | %s | %.3f | %zu | %zu | %.3f | %.3f | %s |\n", row.cloud.c_str(),
                  row.method.c_str(), row.voxel_size_m, row.points_in, row.points_out, row.mean_ms, row.std_ms, ratio);
    out << line;
  }
}

}  // namespace stvl::bench

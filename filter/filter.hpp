#pragma once
// One entry point for the per-frame cloud filter: passthrough on z, then voxel grid or CSNB decimation,
// on the CPU (std::thread) or CUDA. Clouds are Eigen::Matrix3Xf, one column per point, in metres.
#include <Eigen/Core>

#include <memory>
#include <string>

#include "filter/csnb.hpp"
#include "filter/passthrough.hpp"
#include "filter/voxel_grid.hpp"

namespace stvl::filter {

enum class FilterType { kNone, kPassthrough, kVoxel, kCsnb };
enum class Device { kCpu, kCuda, kAuto };
// How clouds move between host and GPU (the paper's four modes). Device intermediates are always cudaMalloc'd.
enum class MemoryMode { kCopy, kPinned, kMapped, kManaged };

// Parse "none|passthrough|voxel|csnb", "cpu|cuda|auto", "copy|pinned|mapped|managed"; throw
// std::invalid_argument naming the bad string.
FilterType parse_filter_type(const std::string& text);
Device parse_device(const std::string& text);
MemoryMode parse_memory_mode(const std::string& text);
const char* to_string(FilterType type);
const char* to_string(Device device);
const char* to_string(MemoryMode mode);

// True when a CUDA device can be used by this process; otherwise `reason` says why (no GPU, error code,
// or "built without CUDA support").
bool cuda_available(std::string* reason = nullptr);

struct FilterConfig {
  FilterType type = FilterType::kVoxel;
  Device device = Device::kAuto;
  MemoryMode memory = MemoryMode::kCopy;
  bool passthrough_enabled = true;  // passthrough runs before voxel/csnb when enabled (always for type passthrough)
  // How the pipeline (pipeline/sensing.hpp) uses the band. false (the bench's order): the whole cloud is decimated (it
  // clears), then the band picks what marks. true (STVL's measurement buffer with `filter: voxel`: PCL's VoxelGrid
  // with z filter limits): the band first, then the decimation, whose output both marks and clears.
  bool band_before_decimation = false;  // YAML filter.passthrough.before_decimation
  PassthroughConfig passthrough;
  VoxelGridConfig voxel;
  CsnbConfig csnb;
  int cpu_threads = 0;  // 0: std::thread::hardware_concurrency()
};

namespace cuda {
class Context;
}

// Holds the GPU workspace between frames. kAuto without a GPU runs on the CPU and prints one notice per
// process to stderr; kCuda without a GPU throws std::runtime_error. Not thread-safe.
class Filter {
 public:
  explicit Filter(FilterConfig config);
  ~Filter();
  Filter(Filter&&) noexcept;
  Filter& operator=(Filter&&) noexcept;

  Eigen::Matrix3Xf apply(const Eigen::Matrix3Xf& points_W);
  const char* device_used() const { return use_cuda_ ? "cuda" : "cpu"; }
  const FilterConfig& config() const { return config_; }

 private:
  FilterConfig config_;
  bool use_cuda_ = false;
  std::unique_ptr<cuda::Context> cuda_;
};

}  // namespace stvl::filter

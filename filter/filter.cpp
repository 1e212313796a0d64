#include "filter/filter.hpp"

#include <cmath>
#include <cstdio>
#include <mutex>
#include <stdexcept>

#include "common/enum_names.hpp"
#include "filter/cuda/context.hpp"
#include "filter/detail/common.hpp"

namespace stvl::filter {

namespace {
constexpr EnumName<FilterType> kTypeNames[] = {{FilterType::kNone, "none"},
                                               {FilterType::kPassthrough, "passthrough"},
                                               {FilterType::kVoxel, "voxel"},
                                               {FilterType::kCsnb, "csnb"}};
constexpr EnumName<Device> kDeviceNames[] = {{Device::kCpu, "cpu"}, {Device::kCuda, "cuda"}, {Device::kAuto, "auto"}};
constexpr EnumName<MemoryMode> kMemoryNames[] = {{MemoryMode::kCopy, "copy"},
                                                 {MemoryMode::kPinned, "pinned"},
                                                 {MemoryMode::kMapped, "mapped"},
                                                 {MemoryMode::kManaged, "managed"}};

// parse_enum's message, "filter: " in front (config errors name the module that threw them).
template <class E, std::size_t N>
E parse(const std::string& text, const EnumName<E> (&names)[N], const char* what) {
  try {
    return parse_enum(text, names, what);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("filter: ") + e.what());
  }
}
}  // namespace

FilterType parse_filter_type(const std::string& text) { return parse(text, kTypeNames, "filter type"); }
Device parse_device(const std::string& text) { return parse(text, kDeviceNames, "device"); }
MemoryMode parse_memory_mode(const std::string& text) { return parse(text, kMemoryNames, "memory mode"); }
const char* to_string(FilterType type) { return enum_name(type, kTypeNames); }
const char* to_string(Device device) { return enum_name(device, kDeviceNames); }
const char* to_string(MemoryMode mode) { return enum_name(mode, kMemoryNames); }

bool cuda_available(std::string* reason) {
  static std::once_flag once;
  static bool available = false;
  static std::string why;
  std::call_once(once, [] { available = cuda::device_available(&why); });
  if (reason) *reason = why;
  return available;
}

Eigen::Matrix3Xf passthrough(const Eigen::Matrix3Xf& points_W, const PassthroughConfig& config) {
  if (std::isnan(config.min_z_m) || std::isnan(config.max_z_m) || config.min_z_m > config.max_z_m) {
    throw std::invalid_argument("passthrough: need min_z_m <= max_z_m, got min_z_m=" + std::to_string(config.min_z_m) +
                                " max_z_m=" + std::to_string(config.max_z_m));
  }
  const float* p = points_W.data();
  const Eigen::Index n = points_W.cols();
  auto keep = [&](Eigen::Index i) {
    return detail::finite3(p[3 * i], p[3 * i + 1], p[3 * i + 2]) && p[3 * i + 2] >= config.min_z_m &&
           p[3 * i + 2] <= config.max_z_m;
  };
  Eigen::Index kept = 0;
  for (Eigen::Index i = 0; i < n; ++i) kept += keep(i);
  Eigen::Matrix3Xf out(3, kept);
  for (Eigen::Index i = 0, o = 0; i < n; ++i) {
    if (keep(i)) out.col(o++) = points_W.col(i);
  }
  return out;
}

Filter::Filter(FilterConfig config) : config_(config) {
  if (config_.type == FilterType::kVoxel) detail::validate(config_.voxel);
  if (config_.type == FilterType::kCsnb) detail::validate(config_.csnb);
  if (config_.cpu_threads < 0) {
    throw std::invalid_argument("filter: cpu_threads must be >= 0, got " + std::to_string(config_.cpu_threads));
  }
  const bool decimates = config_.type == FilterType::kVoxel || config_.type == FilterType::kCsnb;
  if (config_.device == Device::kCpu || !decimates) return;
  std::string reason;
  if (!cuda_available(&reason)) {
    if (config_.device == Device::kCuda) throw std::runtime_error("filter: device 'cuda' unavailable: " + reason);
    static std::once_flag notice;
    std::call_once(
        notice, [&] { std::fprintf(stderr, "stvl filter: no usable GPU (%s); running on the CPU\n", reason.c_str()); });
    return;
  }
  cuda_ = std::make_unique<cuda::Context>();
  use_cuda_ = true;
}

Filter::~Filter() = default;
Filter::Filter(Filter&&) noexcept = default;
Filter& Filter::operator=(Filter&&) noexcept = default;

Eigen::Matrix3Xf Filter::apply(const Eigen::Matrix3Xf& points_W) {
  if (config_.type == FilterType::kNone) return points_W;
  const bool pass = config_.type == FilterType::kPassthrough || config_.passthrough_enabled;
  Eigen::Matrix3Xf passed;
  if (pass) passed = passthrough(points_W, config_.passthrough);
  const Eigen::Matrix3Xf& in = pass ? passed : points_W;
  switch (config_.type) {
    case FilterType::kVoxel:
      return use_cuda_ ? cuda_->voxel_grid(in, config_.voxel, config_.memory)
                       : voxel_grid(in, config_.voxel, config_.cpu_threads);
    case FilterType::kCsnb:
      return use_cuda_ ? cuda_->csnb(in, config_.csnb, config_.memory) : csnb(in, config_.csnb, config_.cpu_threads);
    default: return passed;
  }
}

}  // namespace stvl::filter

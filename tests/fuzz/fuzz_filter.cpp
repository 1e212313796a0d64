// Cloud filters through filter::Filter (CPU): arbitrary clouds (NaN, Inf, denormals, huge coordinates),
// voxel sizes and configs. A call either returns a cloud of finite points, no larger than the input, or
// throws std::invalid_argument.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>

#include "filter/filter.hpp"
#include "fuzz_values.hpp"

using stvl::fuzz::any_value;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  stvl::filter::FilterConfig config;
  config.device = stvl::filter::Device::kCpu;
  config.type = static_cast<stvl::filter::FilterType>(in.ConsumeIntegralInRange<int>(0, 3));
  config.passthrough_enabled = in.ConsumeBool();
  config.passthrough.min_z_m = any_value<double>(in, -5.0, 5.0);
  config.passthrough.max_z_m = any_value<double>(in, -5.0, 5.0);
  config.voxel.voxel_size_m = any_value<double>(in, 1e-4, 2.0);
  config.voxel.min_points_per_voxel = in.ConsumeIntegralInRange<int>(-2, 5);
  config.csnb.voxel_size_m = any_value<double>(in, 1e-4, 2.0);
  config.csnb.max_neighbours = in.ConsumeIntegralInRange<int>(-1, 40);
  config.csnb.batch_size = in.ConsumeIntegralInRange<int>(-1, 64);
  config.csnb.grid_exponent = in.ConsumeIntegralInRange<int>(-1, 10);
  config.csnb.seed = in.ConsumeIntegral<std::uint64_t>();
  config.cpu_threads = in.ConsumeIntegralInRange<int>(0, 4);

  const int n = in.ConsumeIntegralInRange<int>(0, 2048);
  Eigen::Matrix3Xf cloud(3, n);
  const float spread = any_value<float>(in, 0.01f, 100.0f);
  for (int i = 0; i < n && in.remaining_bytes() > 0; ++i)
    for (int r = 0; r < 3; ++r)
      cloud(r, i) = in.ConsumeBool() ? any_value<float>(in, -1.0f, 1.0f)
                                     : spread * in.ConsumeFloatingPointInRange<float>(-1.0f, 1.0f);

  Eigen::Matrix3Xf out;
  try {
    stvl::filter::Filter filter(config);
    out = filter.apply(cloud);
    if (in.ConsumeBool()) out = filter.apply(cloud);  // the workspace kept between frames
  } catch (const std::invalid_argument&) {
    return 0;
  }
  if (config.type != stvl::filter::FilterType::kNone) {
    if (out.cols() > cloud.cols() || !out.allFinite()) std::abort();
  } else if (out.cols() != cloud.cols()) {
    std::abort();
  }
  return 0;
}

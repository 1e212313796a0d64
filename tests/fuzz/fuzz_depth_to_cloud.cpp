// Depth to cloud: arbitrary depth values (NaN, Inf, negative, denormal, huge), intrinsics and image sizes,
// including images whose depth vector disagrees with width x height. Either std::invalid_argument or a cloud of
// at most one point per valid pixel (z > 0, never NaN); with intrinsics that pass validate(), a point whose
// exact coordinates fit in a float comes out finite. (Invalid intrinsics are not rejected by depth_to_cloud: their
// points are only required not to crash; see docs/reliability.md.)
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "fuzz_values.hpp"
#include "sensors/depth_image.hpp"

using stvl::fuzz::any_value;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  stvl::sensors::CameraIntrinsics k;
  k.width = in.ConsumeIntegralInRange<int>(-2, 64);
  k.height = in.ConsumeIntegralInRange<int>(-2, 64);
  k.fx = any_value<double>(in, 1.0, 1000.0);
  k.fy = in.ConsumeBool() ? k.fx : any_value<double>(in, 1.0, 1000.0);
  k.cx = any_value<double>(in, -10.0, 70.0);
  k.cy = any_value<double>(in, -10.0, 70.0);
  k.min_range_m = any_value<double>(in, 0.0, 1.0);
  k.max_range_m = any_value<double>(in, 0.5, 20.0);

  stvl::sensors::DepthImage image;
  const int mode = in.ConsumeIntegralInRange<int>(0, 7);
  image.width = mode == 0 ? in.ConsumeIntegralInRange<int>(-2, 64) : k.width;
  image.height = mode == 1 ? in.ConsumeIntegralInRange<int>(-2, 64) : k.height;
  std::size_t values = image.width > 0 && image.height > 0 ? std::size_t(image.width) * image.height : 0;
  if (mode == 2) values = in.ConsumeIntegralInRange<std::size_t>(0, 4096);
  image.depth_m.resize(values);
  for (auto& z : image.depth_m)
    z = in.ConsumeBool() ? any_value<float>(in, -1.0f, 20.0f) : in.ConsumeFloatingPointInRange<float>(0.0f, 12.0f);

  Eigen::Matrix3Xf cloud;
  Eigen::Index n = 0;
  try {
    if (in.ConsumeBool()) {
      cloud = stvl::sensors::depth_to_cloud(image, k);
      n = cloud.cols();
    } else {
      cloud.resize(3, in.ConsumeIntegralInRange<int>(0, 8));  // a reused buffer, maybe too small
      n = stvl::sensors::depth_to_cloud(image, k, cloud);
      if (n > cloud.cols()) std::abort();
    }
  } catch (const std::invalid_argument&) {
    return 0;
  }
  if (n > image.valid_count()) std::abort();
  bool intrinsics_valid = true;
  try {
    k.validate();
  } catch (const std::invalid_argument&) {
    intrinsics_valid = false;
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    const float z = cloud(2, i);
    if (!(z > 0.0f)) std::abort();
    // Exact |x|, |y| bounds over the image: a point that fits in a float must come out finite.
    const double x_max = std::max(std::abs(k.cx), std::abs(k.width - 1 - k.cx)) / k.fx * double(z);
    const double y_max = std::max(std::abs(k.cy), std::abs(k.height - 1 - k.cy)) / k.fy * double(z);
    if (intrinsics_valid && x_max < 1e37 && y_max < 1e37 && !cloud.col(i).allFinite()) {
      std::fprintf(stderr, "non-finite point (%g, %g, %g) from valid intrinsics %dx%d fx %g fy %g cx %g cy %g\n",
                   cloud(0, i), cloud(1, i), z, k.width, k.height, k.fx, k.fy, k.cx, k.cy);
      std::abort();
    }
  }
  return 0;
}

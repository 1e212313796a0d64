#pragma once
// The plain twin of sensors/depth_noise.hpp: the noise model as it was before its vectorized rewrite (issue 32),
// kept verbatim. tests/sensors compares the two (equal images, bit for bit); linked by tests only.
#include <cstdint>
#include <vector>

#include "sensors/camera.hpp"
#include "sensors/depth_image.hpp"
#include "sensors/depth_noise.hpp"

namespace stvl::sensors::reference {

class DepthNoise {
 public:
  // Validates both as sensors::DepthNoise does (throws std::invalid_argument).
  DepthNoise(const DepthNoiseConfig& config, const CameraIntrinsics& intrinsics);

  // sensors::DepthNoise::apply pixel by pixel (rows in parallel with TBB when parallel is true; same image).
  void apply(DepthImage& image, uint64_t seed, uint64_t frame_index, bool parallel = true);

 private:
  DepthNoiseConfig config_;
  CameraIntrinsics intrinsics_;
  std::vector<float> truth_;
  std::vector<uint8_t> occluded_;
  std::vector<float> field_grid_;
};

}  // namespace stvl::sensors::reference

#pragma once
// The plain twin of sensors/camera.hpp's depth_to_cloud: one loop over the pixels in row-major order, written
// from its comment. tests/sensors compares the two (the same points, bit for bit); linked by tests only.
#include <Eigen/Core>

#include "sensors/camera.hpp"
#include "sensors/depth_image.hpp"

namespace stvl::sensors::reference {

// The valid pixels' points in the camera's optical frame (m), in row-major pixel order: for a finite depth
// z > 0 at (u, v), ((u - cx) / fx * z, (v - cy) / fy * z, z) in float, the reciprocals taken in double.
Eigen::Matrix3Xf depth_to_cloud(const DepthImage& image, const CameraIntrinsics& k);

}  // namespace stvl::sensors::reference

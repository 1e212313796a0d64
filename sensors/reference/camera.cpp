#include "sensors/reference/camera.hpp"

#include <cmath>
#include <vector>

namespace stvl::sensors::reference {

Eigen::Matrix3Xf depth_to_cloud(const DepthImage& image, const CameraIntrinsics& k) {
  std::vector<Eigen::Vector3f> points;
  for (int v = 0; v < k.height; ++v)
    for (int u = 0; u < k.width; ++u) {
      const float z = image.at(u, v);
      if (!(z > 0.0f) || !std::isfinite(z)) continue;
      points.emplace_back((float(u) - float(k.cx)) * float(1.0 / k.fx) * z,
                          (float(v) - float(k.cy)) * float(1.0 / k.fy) * z, z);
    }
  Eigen::Matrix3Xf cloud(3, Eigen::Index(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i) cloud.col(Eigen::Index(i)) = points[i];
  return cloud;
}

}  // namespace stvl::sensors::reference

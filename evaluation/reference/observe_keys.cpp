#include "evaluation/reference/observe_keys.hpp"

#include <algorithm>

namespace stvl::evaluation::reference {

void observed_keys(const sensors::DepthImage& depth, const sensors::CameraIntrinsics& k,
                   const Eigen::Isometry3d& T_world_camera, double obstacle_range_m, const EvaluationConfig& config,
                   std::vector<VoxelKey>& keys) {
  keys.clear();
  const Eigen::Isometry3f T = T_world_camera.cast<float>();
  for (int v = 0; v < depth.height; v += kObserveStride) {
    const float ray_y = static_cast<float>((v - k.cy) / k.fy);
    for (int u = 0; u < depth.width; u += kObserveStride) {
      const float ray_x = static_cast<float>((u - k.cx) / k.fx);
      const float z = depth.at(u, v);
      if (!(z > 0.0f)) continue;
      const Eigen::Vector3f p_C = z * Eigen::Vector3f(ray_x, ray_y, 1.0f);
      if (p_C.norm() > obstacle_range_m) continue;
      const Eigen::Vector3d p_W = (T * p_C).cast<double>();
      if (p_W.z() < config.min_obstacle_height_m || p_W.z() > config.max_obstacle_height_m) continue;
      if (!p_W.allFinite()) continue;  // an Inf depth with an infinite range: no voxel (the renderer gives none)
      keys.push_back(voxel_key(p_W, config.voxel_size_m));
    }
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
}

}  // namespace stvl::evaluation::reference

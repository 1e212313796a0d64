#include "sensors/reference/depth_renderer.hpp"

namespace stvl::sensors::reference {

DepthImage ray_cast_depth(const mjModel* model, const mjData* data, const CameraIntrinsics& k,
                          const Eigen::Isometry3d& T_world_camera, std::array<bool, 6> groups) {
  DepthImage image(k.width, k.height);
  mjtByte geomgroup[mjNGROUP];
  for (int g = 0; g < mjNGROUP; ++g) geomgroup[g] = groups[size_t(g)];
  const Eigen::Vector3d origin = T_world_camera.translation();
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const Eigen::Vector3d direction = T_world_camera.linear() * pixel_ray_C(k, u, v);  // z component 1 in C
      int geom = -1;
      // mj_ray's distance is in units of |direction|, and direction has optical z = 1: it is the depth.
      const double z = mj_ray(model, data, origin.data(), direction.data(), geomgroup, 1, -1, &geom);
      image.at(u, v) = (z >= k.min_range_m && z <= k.max_range_m) ? float(z) : 0.0f;
    }
  }
  return image;
}

}  // namespace stvl::sensors::reference

#pragma once
// Tiny MJCF worlds loaded from strings, and mj_ray ground truth per pixel.
#include "sensors/camera.hpp"
#include "sensors/depth_image.hpp"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <Eigen/Geometry>

#include <array>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>

#include <unistd.h>

namespace stvl::sensors::testing {

struct World {
  mjModel* model = nullptr;
  mjData* data = nullptr;
  explicit World(const std::string& xml) {
    const std::string path = ::testing::TempDir() + "stvl_sensors_world_" + std::to_string(::getpid()) + ".xml";
    std::ofstream(path) << xml;
    char error[1000] = "";
    model = mj_loadXML(path.c_str(), nullptr, error, sizeof(error));
    std::remove(path.c_str());
    if (!model) throw std::runtime_error(std::string("test world: ") + error);
    data = mj_makeData(model);
    mj_forward(model, data);
  }
  ~World() {
    mj_deleteData(data);
    mj_deleteModel(model);
  }
  World(const World&) = delete;
  World& operator=(const World&) = delete;
};

// Optical frame looking along world +x from `position` (x right = world -y, y down = world -z), then rotated by
// `extra` about the optical axes.
inline Eigen::Isometry3d looking_along_x(const Eigen::Vector3d& position,
                                         const Eigen::Matrix3d& extra = Eigen::Matrix3d::Identity()) {
  Eigen::Matrix3d R;
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R * extra;
  T.translation() = position;
  return T;
}

// Depth along the optical axis from mj_ray through each pixel centre, same range rule as the renderer.
inline DepthImage ray_cast_depth(const World& world, const CameraIntrinsics& k, const Eigen::Isometry3d& T_world_camera,
                                 std::array<bool, 6> groups = {true, true, false, true, true, true}) {
  DepthImage image(k.width, k.height);
  mjtByte geomgroup[mjNGROUP];
  for (int g = 0; g < mjNGROUP; ++g) geomgroup[g] = groups[size_t(g)];
  const Eigen::Vector3d origin = T_world_camera.translation();
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const Eigen::Vector3d direction = T_world_camera.linear() * pixel_ray_C(k, u, v);  // z component 1 in C
      int geom = -1;
      // mj_ray's distance is in units of |direction|, and direction has optical z = 1: it is the depth.
      const double z = mj_ray(world.model, world.data, origin.data(), direction.data(), geomgroup, 1, -1, &geom);
      image.at(u, v) = (z >= k.min_range_m && z <= k.max_range_m) ? float(z) : 0.0f;
    }
  }
  return image;
}

}  // namespace stvl::sensors::testing

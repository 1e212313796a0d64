#pragma once
// The plain twin of sensors/depth_renderer.hpp: depth per pixel from MuJoCo's mj_ray instead of OpenGL.
// tests/sensors compares the rendered images with it; linked by tests only.
#include <mujoco/mujoco.h>

#include <Eigen/Geometry>

#include <array>

#include "sensors/camera.hpp"
#include "sensors/depth_image.hpp"

namespace stvl::sensors::reference {

// Depth along the optical axis (m) of the first geom hit by mj_ray through each pixel centre from
// T_world_camera (optical frame: z forward, x right, y down), 0 where nothing is hit within
// [k.min_range_m, k.max_range_m] (the renderer's range rule). `groups` are the geom groups drawn (the
// renderer's default hides group 2, the robot's). model and data must not be null.
DepthImage ray_cast_depth(const mjModel* model, const mjData* data, const CameraIntrinsics& k,
                          const Eigen::Isometry3d& T_world_camera,
                          std::array<bool, 6> groups = {true, true, false, true, true, true});

}  // namespace stvl::sensors::reference

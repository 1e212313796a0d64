#pragma once
// Off-screen metric depth rendering of a MuJoCo 2.2.2 scene from any optical-frame pose.
#include "sensors/camera.hpp"
#include "sensors/depth_image.hpp"
#include "sensors/gl_context.hpp"

#include <mujoco/mujoco.h>

#include <Eigen/Geometry>

#include <array>
#include <memory>

namespace stvl::sensors {

class DepthRenderer {
 public:
  // model: not null; must outlive nothing (a copy configures the GL context: MSAA off, offscreen buffer enlarged to
  // the image, finer sphere/cylinder tessellation), but render() must be given the same model or one with the same
  // geoms and meshes. intrinsics: validated, square pixels required (fx == fy; MuJoCo 2.2.2 only renders square
  // pixels). visible_geom_groups[g]: render geoms of group g (the robot's own geoms are in group 2, those
  // a scenario lets the cameras see in group 3: sim::World::show_robot_geoms_to_cameras).
  // Throws std::invalid_argument for bad input, std::runtime_error when no GL context can be made.
  DepthRenderer(const mjModel* model, const CameraIntrinsics& intrinsics, GlBackend backend = GlBackend::kAuto,
                std::array<bool, 6> visible_geom_groups = {true, true, false, true, true, true});
  ~DepthRenderer();
  DepthRenderer(const DepthRenderer&) = delete;
  DepthRenderer& operator=(const DepthRenderer&) = delete;

  // T_world_camera: the optical frame (z forward, x right, y down) in the world. data must hold current kinematics
  // (mj_forward or mj_step ran). Depth along the optical axis in metres; 0 where nothing was hit within
  // [min_range_m, max_range_m]. The returned image is owned by the renderer and overwritten by the next call.
  const DepthImage& render(const mjModel* model, mjData* data, const Eigen::Isometry3d& T_world_camera);

  const CameraIntrinsics& intrinsics() const;
  GlBackend backend() const;
  const char* backend_name() const;  // "egl" or "osmesa"
  double znear_m() const;            // GL near plane: geometry closer than this is not drawn

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace stvl::sensors

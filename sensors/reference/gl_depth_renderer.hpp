#pragma once
// The plain twin of DepthRenderer's GL path: the renderer as it was before its readback was optimized (colour
// writes on, mjr_readPixels of float depth, the same conversion to metres). Tests compare every pixel of the
// optimized renderer with it; linked by tests only.
#include <mujoco/mujoco.h>

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <memory>

#include "sensors/camera.hpp"
#include "sensors/depth_image.hpp"
#include "sensors/gl_context.hpp"

namespace stvl::sensors::reference {

// Mesa 22's glReadPixels(GL_DEPTH_COMPONENT, GL_FLOAT) of a 24-bit depth word (depth << 8 | stencil): z24 / 0xffffff.
float mesa_float_depth(std::uint32_t z24s8);
// The renderer's conversion of one GL float depth d (0..1) to metres, as it was: 0 where d >= 1, else
// z = near / (1 - d (1 - near / far)) in double, 0 outside [min_m, max_m].
float depth_m_from_gl_depth(float d, double near_m, double far_m, float min_m, float max_m);

class FloatDepthRenderer {
 public:
  // As DepthRenderer's constructor (same model copy, scene and GL settings).
  FloatDepthRenderer(const mjModel* model, const CameraIntrinsics& intrinsics, GlBackend backend = GlBackend::kAuto,
                     std::array<bool, 6> visible_geom_groups = {true, true, false, true, true, true});
  ~FloatDepthRenderer();
  FloatDepthRenderer(const FloatDepthRenderer&) = delete;
  FloatDepthRenderer& operator=(const FloatDepthRenderer&) = delete;

  // As DepthRenderer::render: depth along the optical axis (m), 0 outside [min_range_m, max_range_m].
  const DepthImage& render(const mjModel* model, mjData* data, const Eigen::Isometry3d& T_world_camera);
  const char* backend_name() const;  // "egl" or "osmesa"

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace stvl::sensors::reference

// DepthRenderer's readback as it was before it was optimized (kept as the reference): colour writes on,
// mjr_readPixels of the depth as float (Mesa converts the 24-bit depth), then the plain conversion to metres. The
// scene, its GL camera and the context are DepthRenderer's own (sensors/mujoco_scene.hpp): only the readback is
// compared. What sensors/depth_renderer.cpp must reproduce bit for bit.
#include "sensors/reference/gl_depth_renderer.hpp"

#include <vector>

#include "sensors/mujoco_scene.hpp"

namespace stvl::sensors::reference {

struct FloatDepthRenderer::Impl {
  Impl(const mjModel* model, const CameraIntrinsics& intrinsics, GlBackend backend, const std::array<bool, 6>& groups)
      : mj(model, intrinsics, backend, groups, "FloatDepthRenderer") {}
  MujocoScene mj;               // the scene, its camera and the GL context as DepthRenderer makes them
  std::vector<float> gl_depth;  // rows bottom first, as glReadPixels returns them
  DepthImage image;
};

FloatDepthRenderer::FloatDepthRenderer(const mjModel* model, const CameraIntrinsics& intrinsics, GlBackend backend,
                                       std::array<bool, 6> visible_geom_groups)
    : impl_(std::make_unique<Impl>(model, intrinsics, backend, visible_geom_groups)) {
  impl_->gl_depth.resize(size_t(intrinsics.width) * intrinsics.height);
  impl_->image = DepthImage(intrinsics.width, intrinsics.height);
}

FloatDepthRenderer::~FloatDepthRenderer() = default;

const DepthImage& FloatDepthRenderer::render(const mjModel* model, mjData* data,
                                             const Eigen::Isometry3d& T_world_camera) {
  Impl& s = *impl_;
  s.mj.update(model, data, T_world_camera);
  s.mj.gl->make_current();
  ThrowOnMujocoError guard;
  const CameraIntrinsics& k = s.mj.intrinsics;
  const mjvGLCamera& gl_camera = s.mj.scene.camera[0];
  const mjrRect viewport{0, 0, k.width, k.height};
  mjr_setBuffer(mjFB_OFFSCREEN, &s.mj.context);
  mjr_render(viewport, &s.mj.scene, &s.mj.context);
  mjr_readPixels(nullptr, s.gl_depth.data(), viewport, &s.mj.context);

  // Standard (not reversed) Z in MuJoCo 2.2.2: z = n / (1 - d (1 - n / f)); d = 1 is the far plane (no hit).
  // Same float constants as GL used, in double for the cancellation near d = 1.
  const double near = double(gl_camera.frustum_near), far = double(gl_camera.frustum_far);
  const float min_m = float(k.min_range_m), max_m = float(k.max_range_m);
  for (int row = 0; row < k.height; ++row) {
    const float* in = s.gl_depth.data() + size_t(k.height - 1 - row) * k.width;
    float* out = s.image.depth_m.data() + size_t(row) * k.width;
    for (int u = 0; u < k.width; ++u) out[u] = depth_m_from_gl_depth(in[u], near, far, min_m, max_m);
  }
  return s.image;
}

float mesa_float_depth(std::uint32_t z24s8) {
  const double scale = 1.0 / double(0xffffff);
  return float((z24s8 >> 8) * scale);
}

float depth_m_from_gl_depth(float d, double near_m, double far_m, float min_m, float max_m) {
  // Standard (not reversed) Z in MuJoCo 2.2.2: z = n / (1 - d (1 - n / f)); d = 1 is the far plane (no hit).
  // Same float constants as GL used, in double for the cancellation near d = 1.
  const double scale = 1.0 - near_m / far_m;
  float z = 0.0f;
  if (d < 1.0f) {
    z = float(near_m / (1.0 - double(d) * scale));
    if (!(z >= min_m && z <= max_m)) z = 0.0f;
  }
  return z;
}

const char* FloatDepthRenderer::backend_name() const { return to_string(impl_->mj.gl->backend()); }

}  // namespace stvl::sensors::reference

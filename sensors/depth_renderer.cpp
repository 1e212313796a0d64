#include "sensors/depth_renderer.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstdint>
#include <exception>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "sensors/mujoco_scene.hpp"

namespace stvl::sensors {
namespace {

// The GL calls the renderer makes itself (MuJoCo's own GL binding is not exported).
constexpr unsigned kGlDepthStencil = 0x84F9;    // GL_DEPTH_STENCIL
constexpr unsigned kGlUnsignedInt248 = 0x84FA;  // GL_UNSIGNED_INT_24_8: depth in the upper 24 bits
using GlColorMask = void (*)(unsigned char, unsigned char, unsigned char, unsigned char);
using GlReadPixels = void (*)(int, int, int, int, unsigned, unsigned, void*);

}  // namespace

struct DepthRenderer::Impl {
  Impl(const mjModel* model, const CameraIntrinsics& intrinsics, GlBackend backend, const std::array<bool, 6>& groups)
      : mj(model, intrinsics, backend, groups, "DepthRenderer") {
    mj.cull_outside_view = true;
  }
  MujocoScene mj;
  GlColorMask gl_color_mask = nullptr;
  GlReadPixels gl_read_pixels = nullptr;
  bool prepared = false;
  // Depth and stencil as GL_UNSIGNED_INT_24_8 (depth << 8 | stencil), rows bottom first as glReadPixels returns
  // them: Mesa's own Z24S8 layout, a copy of the buffer instead of its conversion to float.
  std::vector<std::uint32_t> gl_depth_stencil;
  DepthImage image;
};

DepthRenderer::DepthRenderer(const mjModel* model, const CameraIntrinsics& intrinsics, GlBackend backend,
                             std::array<bool, 6> visible_geom_groups)
    : impl_(std::make_unique<Impl>(model, intrinsics, backend, visible_geom_groups)) {
  Impl& s = *impl_;
  s.gl_color_mask = reinterpret_cast<GlColorMask>(s.mj.gl->proc_address("glColorMask"));
  s.gl_read_pixels = reinterpret_cast<GlReadPixels>(s.mj.gl->proc_address("glReadPixels"));
  if (!s.gl_color_mask || !s.gl_read_pixels) {
    throw std::runtime_error("DepthRenderer: " + std::string(to_string(s.mj.gl->backend())) +
                             " has no glColorMask or glReadPixels");
  }
  s.gl_depth_stencil.resize(size_t(intrinsics.width) * intrinsics.height);
  s.image = DepthImage(intrinsics.width, intrinsics.height);
}

DepthRenderer::~DepthRenderer() = default;

const DepthImage& DepthRenderer::render(const mjModel* model, mjData* data, const Eigen::Isometry3d& T_world_camera) {
  prepare(model, data, T_world_camera);
  return draw();
}

void DepthRenderer::prepare(const mjModel* model, mjData* data, const Eigen::Isometry3d& T_world_camera) {
  impl_->prepared = false;
  impl_->mj.update(model, data, T_world_camera);
  impl_->prepared = true;
}

const DepthImage& DepthRenderer::draw() {
  Impl& s = *impl_;
  if (!s.prepared) throw std::logic_error("DepthRenderer::draw: no prepare() since the last draw()");
  s.prepared = false;
  const CameraIntrinsics& k = s.mj.intrinsics;
  const mjvGLCamera& gl_camera = s.mj.scene.camera[0];
  s.mj.gl->make_current();
  ThrowOnMujocoError guard;
  const mjrRect viewport{0, 0, k.width, k.height};
  mjr_setBuffer(mjFB_OFFSCREEN, &s.mj.context);
  // Depth only: segmentation mode draws flat colours nobody reads, and no colour test (blend, alpha) is on, so
  // masking colour writes (and the colour clear) leaves every depth value as it was, at less raster work.
  s.gl_color_mask(0, 0, 0, 0);
  mjr_render(viewport, &s.mj.scene, &s.mj.context);
  // mjr_render left the offscreen framebuffer bound (mjr_restoreBuffer); read its Z24S8 buffer as it is stored.
  s.gl_read_pixels(0, 0, k.width, k.height, kGlDepthStencil, kGlUnsignedInt248, s.gl_depth_stencil.data());

  const double near = double(gl_camera.frustum_near), far = double(gl_camera.frustum_far);
  const float min_m = float(k.min_range_m), max_m = float(k.max_range_m);
  // Each pixel on its own (a division each): rows in parallel, the same image. GL rows are bottom first.
  tbb::parallel_for(tbb::blocked_range<int>(0, k.height, 32), [&](const tbb::blocked_range<int>& rows) {
    for (int row = rows.begin(); row < rows.end(); ++row) {
      depth_m_from_z24s8(s.gl_depth_stencil.data() + size_t(k.height - 1 - row) * k.width,
                         s.image.depth_m.data() + size_t(row) * k.width, k.width, near, far, min_m, max_m);
    }
  });
  return s.image;
}

void DepthRenderer::release_context() { impl_->mj.gl->release(); }
const DepthImage& DepthRenderer::image() const { return impl_->image; }

void depth_m_from_z24s8(const std::uint32_t* z24s8, float* depth_m, int count, double near_m, double far_m, float min_m,
                        float max_m) {
  // d: what Mesa's glReadPixels(GL_FLOAT) returns for a Z24 buffer (unpack_float_z_X8_UINT_Z24_UNORM and its
  // Z24_X8 twin: (float)(z24 * (1.0 / 0xffffff))), i.e. what mjr_readPixels gave before; tests/sensors checks every
  // z24 value and every pixel of rendered worlds against reference::FloatDepthRenderer.
  // Standard (not reversed) Z in MuJoCo 2.2.2: z = n / (1 - d (1 - n / f)); d = 1 is the far plane (no hit).
  // In double for the cancellation near d = 1. Written without branches (a select) so that it vectorizes: the
  // quotient for d = 1 (about far_m, beyond max_m) or out of range is computed and then dropped.
  const double unorm24 = 1.0 / double(0xffffff);
  const double scale = 1.0 - near_m / far_m;
  for (int u = 0; u < count; ++u) {
    const float d = float(double(std::int32_t(z24s8[u] >> 8)) * unorm24);
    const float z = float(near_m / (1.0 - double(d) * scale));
    const bool keep = (d < 1.0f) & (z >= min_m) & (z <= max_m);
    depth_m[u] = keep ? z : 0.0f;
  }
}

void render_concurrently(const std::vector<DepthRenderer*>& renderers, const mjModel* model, mjData* data,
                         const std::vector<Eigen::Isometry3d>& T_world_camera) {
  if (renderers.size() != T_world_camera.size()) {
    throw std::invalid_argument("render_concurrently: " + std::to_string(renderers.size()) + " renderers, " +
                                std::to_string(T_world_camera.size()) + " poses");
  }
  for (std::size_t i = 0; i < renderers.size(); ++i) {
    if (!renderers[i]) throw std::invalid_argument("render_concurrently: renderer " + std::to_string(i) + " is null");
    for (std::size_t j = 0; j < i; ++j)
      if (renderers[j] == renderers[i]) throw std::invalid_argument("render_concurrently: a renderer appears twice");
  }
  for (std::size_t i = 0; i < renderers.size(); ++i) renderers[i]->prepare(model, data, T_world_camera[i]);
  if (renderers.size() == 1) {
    renderers[0]->draw();
    return;
  }
  ThrowOnMujocoError guard;  // installed once for all threads
  // A context current here (the last render() on this thread) cannot be made current on another thread.
  for (DepthRenderer* r : renderers) r->release_context();
  std::vector<std::exception_ptr> errors(renderers.size());
  std::vector<std::thread> threads;
  threads.reserve(renderers.size() - 1);
  for (std::size_t i = 1; i < renderers.size(); ++i) {
    threads.emplace_back([&, i] {
      try {
        renderers[i]->draw();
        renderers[i]->release_context();
      } catch (...) {
        errors[i] = std::current_exception();
      }
    });
  }
  try {
    renderers[0]->draw();
  } catch (...) {
    errors[0] = std::current_exception();
  }
  for (std::thread& t : threads) t.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

const CameraIntrinsics& DepthRenderer::intrinsics() const { return impl_->mj.intrinsics; }
GlBackend DepthRenderer::backend() const { return impl_->mj.gl->backend(); }
const char* DepthRenderer::backend_name() const { return to_string(impl_->mj.gl->backend()); }
double DepthRenderer::znear_m() const { return impl_->mj.znear_m; }
int DepthRenderer::culled_geoms() const { return impl_->mj.culled_geoms; }

}  // namespace stvl::sensors

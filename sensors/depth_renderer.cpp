#include "sensors/depth_renderer.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace stvl::sensors {
namespace {

// MuJoCo reports fatal errors through mju_user_error (default: print and exit). While we call into the renderer,
// turn them into exceptions; libmujoco is built with unwind tables, so they pass through its C frames. The hook is
// one global: while renderers draw on several threads, the first guard installs it and the last one restores it.
class ThrowOnMujocoError {
 public:
  ThrowOnMujocoError() {
    std::lock_guard<std::mutex> lock(mutex());
    if (depth()++ == 0) {
      previous() = mju_user_error;
      mju_user_error = &raise;
    }
  }
  ~ThrowOnMujocoError() {
    std::lock_guard<std::mutex> lock(mutex());
    if (--depth() == 0) mju_user_error = previous();
  }
  ThrowOnMujocoError(const ThrowOnMujocoError&) = delete;
  ThrowOnMujocoError& operator=(const ThrowOnMujocoError&) = delete;

 private:
  static void raise(const char* message) { throw std::runtime_error(std::string("MuJoCo: ") + message); }
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  static int& depth() {
    static int d = 0;
    return d;
  }
  static void (*&previous())(const char*) {
    static void (*p)(const char*) = nullptr;
    return p;
  }
};

// The GL calls the renderer makes itself (MuJoCo's own GL binding is not exported).
constexpr unsigned kGlDepthStencil = 0x84F9;     // GL_DEPTH_STENCIL
constexpr unsigned kGlUnsignedInt248 = 0x84FA;   // GL_UNSIGNED_INT_24_8: depth in the upper 24 bits
using GlColorMask = void (*)(unsigned char, unsigned char, unsigned char, unsigned char);
using GlReadPixels = void (*)(int, int, int, int, unsigned, unsigned, void*);

constexpr int kMinSlices = 32;  // sphere/cylinder tessellation: chord error 1 - cos(pi/32) = 0.5 % of the radius
constexpr int kMinStacks = 16;

}  // namespace

struct DepthRenderer::Impl {
  CameraIntrinsics intrinsics;
  std::unique_ptr<GlContext> gl;
  mjvScene scene{};
  mjrContext context{};
  mjvOption option{};
  mjvCamera camera{};
  bool scene_made = false;
  bool context_made = false;
  int ngeom = 0, nmesh = 0;
  double znear_m = 0.0, zfar_m = 0.0;
  GlColorMask gl_color_mask = nullptr;
  GlReadPixels gl_read_pixels = nullptr;
  bool prepared = false;
  // Depth and stencil as GL_UNSIGNED_INT_24_8 (depth << 8 | stencil), rows bottom first as glReadPixels returns
  // them: Mesa's own Z24S8 layout, a copy of the buffer instead of its conversion to float.
  std::vector<std::uint32_t> gl_depth_stencil;
  DepthImage image;

  ~Impl() {
    if (gl) {
      try {
        gl->make_current();
      } catch (const std::exception&) {
      }
    }
    if (context_made) mjr_freeContext(&context);
    if (scene_made) mjv_freeScene(&scene);
  }
};

DepthRenderer::DepthRenderer(const mjModel* model, const CameraIntrinsics& intrinsics, GlBackend backend,
                             std::array<bool, 6> visible_geom_groups)
    : impl_(std::make_unique<Impl>()) {
  if (!model) throw std::invalid_argument("DepthRenderer: model is null");
  intrinsics.validate();
  if (!intrinsics.square_pixels()) {
    throw std::invalid_argument("DepthRenderer: fx " + std::to_string(intrinsics.fx) + " != fy " +
                                std::to_string(intrinsics.fy) +
                                ": MuJoCo 2.2.2 renders square pixels only (use fx = fy)");
  }
  Impl& s = *impl_;
  s.intrinsics = intrinsics;
  s.ngeom = model->ngeom;
  s.nmesh = model->nmesh;
  // Near plane well inside min range, so that geometry closer than min range still occludes (and reads invalid)
  // instead of being clipped away; far plane beyond max range so that far-plane pixels are unambiguous.
  s.znear_m = std::min(0.05, 0.5 * intrinsics.min_range_m);
  s.zfar_m = 2.0 * intrinsics.max_range_m + 1.0;
  s.gl_depth_stencil.resize(size_t(intrinsics.width) * intrinsics.height);
  s.image = DepthImage(intrinsics.width, intrinsics.height);

  s.gl = GlContext::create(backend);
  s.gl_color_mask = reinterpret_cast<GlColorMask>(s.gl->proc_address("glColorMask"));
  s.gl_read_pixels = reinterpret_cast<GlReadPixels>(s.gl->proc_address("glReadPixels"));
  if (!s.gl_color_mask || !s.gl_read_pixels) {
    throw std::runtime_error("DepthRenderer: " + std::string(to_string(s.gl->backend())) +
                             " has no glColorMask or glReadPixels");
  }

  mjv_defaultOption(&s.option);
  for (int g = 0; g < mjNGROUP; ++g) {
    s.option.geomgroup[g] = visible_geom_groups[size_t(g)] ? 1 : 0;
    s.option.sitegroup[g] = s.option.jointgroup[g] = s.option.tendongroup[g] = 0;
    s.option.actuatorgroup[g] = s.option.skingroup[g] = 0;
  }
  for (int f = 0; f < mjNVISFLAG; ++f) s.option.flags[f] = 0;
  s.option.flags[mjVIS_STATIC] = 1;
  mjv_defaultCamera(&s.camera);

  ThrowOnMujocoError guard;
  mjv_defaultScene(&s.scene);
  mjv_makeScene(model, &s.scene, model->ngeom + 64);
  s.scene_made = true;
  for (int f = 0; f < mjNRNDFLAG; ++f) s.scene.flags[f] = 0;
  // Segmentation mode: flat colour, no lighting, shadows, reflections or skybox: the cheapest pass that still
  // writes the depth buffer for every geom (transparent ones included, as mj_ray sees them).
  s.scene.flags[mjRND_SEGMENT] = 1;
  s.scene.flags[mjRND_CULL_FACE] = 1;
  s.scene.stereo = mjSTEREO_NONE;

  mjModel* copy = mj_copyModel(nullptr, model);
  if (!copy) throw std::runtime_error("DepthRenderer: mj_copyModel failed");
  copy->vis.quality.offsamples = 0;  // MSAA blends silhouette depths (metres off)
  copy->vis.global.offwidth = std::max(copy->vis.global.offwidth, intrinsics.width);
  copy->vis.global.offheight = std::max(copy->vis.global.offheight, intrinsics.height);
  copy->vis.quality.numslices = std::max(copy->vis.quality.numslices, kMinSlices);
  copy->vis.quality.numstacks = std::max(copy->vis.quality.numstacks, kMinStacks);
  for (int i = 0; i < copy->ngeom; ++i) {  // planes: a 2x2 grid, not one quad per `size[2]` (can be ~40k quads)
    if (copy->geom_type[i] != mjGEOM_PLANE) continue;
    mjtNum* size = copy->geom_size + 3 * i;
    size[2] = std::max(size[2], 0.5 * std::max(size[0], size[1]));
  }
  mjr_defaultContext(&s.context);
  try {
    mjr_makeContext(copy, &s.context, mjFONTSCALE_100);
  } catch (...) {
    mj_deleteModel(copy);
    mjr_freeContext(&s.context);
    throw;
  }
  mj_deleteModel(copy);
  s.context_made = true;
  mjr_setBuffer(mjFB_OFFSCREEN, &s.context);
  if (s.context.currentBuffer != mjFB_OFFSCREEN || s.context.offWidth < intrinsics.width ||
      s.context.offHeight < intrinsics.height) {
    throw std::runtime_error("DepthRenderer: " + std::string(to_string(s.gl->backend())) +
                             " offscreen framebuffer " + std::to_string(s.context.offWidth) + "x" +
                             std::to_string(s.context.offHeight) + " unavailable or smaller than needed " +
                             std::to_string(intrinsics.width) + "x" + std::to_string(intrinsics.height));
  }
}

DepthRenderer::~DepthRenderer() = default;

const DepthImage& DepthRenderer::render(const mjModel* model, mjData* data, const Eigen::Isometry3d& T_world_camera) {
  prepare(model, data, T_world_camera);
  return draw();
}

void DepthRenderer::prepare(const mjModel* model, mjData* data, const Eigen::Isometry3d& T_world_camera) {
  Impl& s = *impl_;
  s.prepared = false;
  if (!model || !data) throw std::invalid_argument("DepthRenderer::render: model or data is null");
  if (model->ngeom != s.ngeom || model->nmesh != s.nmesh) {
    throw std::invalid_argument("DepthRenderer::render: model has " + std::to_string(model->ngeom) + " geoms, " +
                                std::to_string(model->nmesh) + " meshes; the renderer was made for " +
                                std::to_string(s.ngeom) + ", " + std::to_string(s.nmesh));
  }
  const Eigen::Matrix3d R = T_world_camera.linear();
  const Eigen::Vector3d p = T_world_camera.translation();
  if (!R.allFinite() || !p.allFinite() ||
      (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 || R.determinant() < 0.0) {
    throw std::invalid_argument("DepthRenderer::render: T_world_camera is not a finite rigid transform");
  }

  ThrowOnMujocoError guard;
  mjv_updateScene(model, data, &s.option, nullptr, &s.camera, mjCAT_STATIC | mjCAT_DYNAMIC, &s.scene);

  // Override the GL camera: OpenGL eye looks along -z_eye = +z optical, with y_eye up = -y optical.
  // Frustum at the near plane n (pixel centres at integer u, v; GL rows bottom first):
  //   top = n (cy + 1/2) / fy, bottom = -n (H - cy - 1/2) / fy, centre = n (W/2 - cx - 1/2) / fx.
  // MuJoCo sets the half width from the viewport aspect: 0.5 W/H (top - bottom) = 0.5 W n / fy (square pixels).
  const CameraIntrinsics& k = s.intrinsics;
  const double n = s.znear_m;
  mjvGLCamera gl_camera{};
  for (int i = 0; i < 3; ++i) {
    gl_camera.pos[i] = float(p[i]);
    gl_camera.forward[i] = float(R(i, 2));
    gl_camera.up[i] = float(-R(i, 1));
  }
  gl_camera.frustum_center = float(n * (0.5 * k.width - k.cx - 0.5) / k.fx);
  gl_camera.frustum_top = float(n * (k.cy + 0.5) / k.fy);
  gl_camera.frustum_bottom = float(-n * (k.height - k.cy - 0.5) / k.fy);
  gl_camera.frustum_near = float(n);
  gl_camera.frustum_far = float(s.zfar_m);
  s.scene.camera[0] = gl_camera;
  s.scene.camera[1] = gl_camera;
  s.scene.enabletransform = 0;
  s.prepared = true;
}

const DepthImage& DepthRenderer::draw() {
  Impl& s = *impl_;
  if (!s.prepared) throw std::logic_error("DepthRenderer::draw: no prepare() since the last draw()");
  s.prepared = false;
  const CameraIntrinsics& k = s.intrinsics;
  const mjvGLCamera& gl_camera = s.scene.camera[0];
  s.gl->make_current();
  ThrowOnMujocoError guard;
  const mjrRect viewport{0, 0, k.width, k.height};
  mjr_setBuffer(mjFB_OFFSCREEN, &s.context);
  // Depth only: segmentation mode draws flat colours nobody reads, and no colour test (blend, alpha) is on, so
  // masking colour writes (and the colour clear) leaves every depth value as it was, at less raster work.
  s.gl_color_mask(0, 0, 0, 0);
  mjr_render(viewport, &s.scene, &s.context);
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

void DepthRenderer::release_context() { impl_->gl->release(); }
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

const CameraIntrinsics& DepthRenderer::intrinsics() const { return impl_->intrinsics; }
GlBackend DepthRenderer::backend() const { return impl_->gl->backend(); }
const char* DepthRenderer::backend_name() const { return to_string(impl_->gl->backend()); }
double DepthRenderer::znear_m() const { return impl_->znear_m; }

}  // namespace stvl::sensors

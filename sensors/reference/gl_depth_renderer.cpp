// Today's DepthRenderer as it was before its readback was optimized (kept as the reference): colour writes on,
// mjr_readPixels of the depth as float (Mesa converts the 24-bit depth), then the plain conversion to metres.
// What sensors/depth_renderer.cpp must reproduce bit for bit.
#include "sensors/reference/gl_depth_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace stvl::sensors::reference {
namespace {

// MuJoCo reports fatal errors through mju_user_error (default: print and exit). While we call into the renderer,
// turn them into exceptions; libmujoco is built with unwind tables, so they pass through its C frames.
class ThrowOnMujocoError {
 public:
  ThrowOnMujocoError() : previous_(mju_user_error) { mju_user_error = &raise; }
  ~ThrowOnMujocoError() { mju_user_error = previous_; }
  ThrowOnMujocoError(const ThrowOnMujocoError&) = delete;
  ThrowOnMujocoError& operator=(const ThrowOnMujocoError&) = delete;

 private:
  static void raise(const char* message) { throw std::runtime_error(std::string("MuJoCo: ") + message); }
  void (*previous_)(const char*);
};

constexpr int kMinSlices = 32;  // sphere/cylinder tessellation: chord error 1 - cos(pi/32) = 0.5 % of the radius
constexpr int kMinStacks = 16;

}  // namespace

struct FloatDepthRenderer::Impl {
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
  std::vector<float> gl_depth;  // rows bottom first, as glReadPixels returns them
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

FloatDepthRenderer::FloatDepthRenderer(const mjModel* model, const CameraIntrinsics& intrinsics, GlBackend backend,
                             std::array<bool, 6> visible_geom_groups)
    : impl_(std::make_unique<Impl>()) {
  if (!model) throw std::invalid_argument("FloatDepthRenderer: model is null");
  intrinsics.validate();
  if (!intrinsics.square_pixels()) {
    throw std::invalid_argument("FloatDepthRenderer: fx " + std::to_string(intrinsics.fx) + " != fy " +
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
  s.gl_depth.resize(size_t(intrinsics.width) * intrinsics.height);
  s.image = DepthImage(intrinsics.width, intrinsics.height);

  s.gl = GlContext::create(backend);

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
  if (!copy) throw std::runtime_error("FloatDepthRenderer: mj_copyModel failed");
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
    throw std::runtime_error("FloatDepthRenderer: " + std::string(to_string(s.gl->backend())) +
                             " offscreen framebuffer " + std::to_string(s.context.offWidth) + "x" +
                             std::to_string(s.context.offHeight) + " unavailable or smaller than needed " +
                             std::to_string(intrinsics.width) + "x" + std::to_string(intrinsics.height));
  }
}

FloatDepthRenderer::~FloatDepthRenderer() = default;

const DepthImage& FloatDepthRenderer::render(const mjModel* model, mjData* data, const Eigen::Isometry3d& T_world_camera) {
  Impl& s = *impl_;
  if (!model || !data) throw std::invalid_argument("FloatDepthRenderer::render: model or data is null");
  if (model->ngeom != s.ngeom || model->nmesh != s.nmesh) {
    throw std::invalid_argument("FloatDepthRenderer::render: model has " + std::to_string(model->ngeom) + " geoms, " +
                                std::to_string(model->nmesh) + " meshes; the renderer was made for " +
                                std::to_string(s.ngeom) + ", " + std::to_string(s.nmesh));
  }
  const Eigen::Matrix3d R = T_world_camera.linear();
  const Eigen::Vector3d p = T_world_camera.translation();
  if (!R.allFinite() || !p.allFinite() ||
      (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 || R.determinant() < 0.0) {
    throw std::invalid_argument("FloatDepthRenderer::render: T_world_camera is not a finite rigid transform");
  }

  s.gl->make_current();
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

  const mjrRect viewport{0, 0, k.width, k.height};
  mjr_setBuffer(mjFB_OFFSCREEN, &s.context);
  mjr_render(viewport, &s.scene, &s.context);
  mjr_readPixels(nullptr, s.gl_depth.data(), viewport, &s.context);

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

const char* FloatDepthRenderer::backend_name() const { return to_string(impl_->gl->backend()); }

}  // namespace stvl::sensors::reference

#include "sensors/mujoco_scene.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <mutex>
#include <stdexcept>

namespace stvl::sensors {
namespace {

constexpr int kMinSlices = 32;  // sphere/cylinder tessellation: chord error 1 - cos(pi/32) = 0.5 % of the radius
constexpr int kMinStacks = 16;

std::mutex& hook_mutex() {
  static std::mutex m;
  return m;
}
int hook_depth = 0;                            // guards alive, under hook_mutex()
void (*hook_previous)(const char*) = nullptr;  // the handler before the first of them
void raise(const char* message) { throw std::runtime_error(std::string("MuJoCo: ") + message); }

// Only the geoms of the visible groups, and no sites, joints, tendons, actuators, skins or decorations.
void set_depth_only_option(mjvOption& option, const std::array<bool, 6>& visible_geom_groups) {
  mjv_defaultOption(&option);
  for (int g = 0; g < mjNGROUP; ++g) {
    option.geomgroup[g] = visible_geom_groups[size_t(g)] ? 1 : 0;
    option.sitegroup[g] = option.jointgroup[g] = option.tendongroup[g] = 0;
    option.actuatorgroup[g] = option.skingroup[g] = 0;
  }
  for (int f = 0; f < mjNVISFLAG; ++f) option.flags[f] = 0;
  option.flags[mjVIS_STATIC] = 1;
}

// Segmentation mode: flat colour, no lighting, shadows, reflections or skybox: the cheapest pass that still
// writes the depth buffer for every geom (transparent ones included, as mj_ray sees them).
void set_segmentation_flags(mjvScene& scene) {
  for (int f = 0; f < mjNRNDFLAG; ++f) scene.flags[f] = 0;
  scene.flags[mjRND_SEGMENT] = 1;
  scene.flags[mjRND_CULL_FACE] = 1;
  scene.stereo = mjSTEREO_NONE;
}

// The rendering context, made from a copy of the model with depth-exact visual settings: no MSAA, an offscreen
// buffer of at least k's size, finer tessellation, planes as a 2x2 grid. On failure `context` is freed.
void make_render_context(const mjModel* model, const CameraIntrinsics& k, const std::string& owner,
                         mjrContext& context) {
  mjModel* copy = mj_copyModel(nullptr, model);
  if (!copy) throw std::runtime_error(owner + ": mj_copyModel failed");
  copy->vis.quality.offsamples = 0;  // MSAA blends silhouette depths (metres off)
  copy->vis.global.offwidth = std::max(copy->vis.global.offwidth, k.width);
  copy->vis.global.offheight = std::max(copy->vis.global.offheight, k.height);
  copy->vis.quality.numslices = std::max(copy->vis.quality.numslices, kMinSlices);
  copy->vis.quality.numstacks = std::max(copy->vis.quality.numstacks, kMinStacks);
  for (int i = 0; i < copy->ngeom; ++i) {  // planes: a 2x2 grid, not one quad per `size[2]` (can be ~40k quads)
    if (copy->geom_type[i] != mjGEOM_PLANE) continue;
    mjtNum* size = copy->geom_size + 3 * i;
    size[2] = std::max(size[2], 0.5 * std::max(size[0], size[1]));
  }
  mjr_defaultContext(&context);
  try {
    mjr_makeContext(copy, &context, mjFONTSCALE_100);
  } catch (...) {
    mj_deleteModel(copy);
    mjr_freeContext(&context);
    throw;
  }
  mj_deleteModel(copy);
}

// Drops from `scene` the geoms whose bounding sphere lies wholly outside the view of a camera at p_W looking
// along R_W_C's z (optical frame: x right, y down), with the image's half-angle tangents tan_x, tan_y (the larger
// side of each axis, so the test does not depend on which way the frustum's centre shifts) and the far plane
// zfar_m. Conservative: a 2 % and 1 cm margin on every radius and the angles widened by 2 %. Returns how many.
int cull_geoms_outside_view(mjvScene& scene, const Eigen::Matrix3d& R_W_C, const Eigen::Vector3d& p_W, double tan_x,
                            double tan_y, double zfar_m) {
  const double nx = 1.0 / std::sqrt(1.0 + tan_x * tan_x), ny = 1.0 / std::sqrt(1.0 + tan_y * tan_y);
  int kept = 0;
  for (int i = 0; i < scene.ngeom; ++i) {
    const mjvGeom& g = scene.geoms[i];
    const double rbound = double(g.modelrbound);
    bool outside = false;
    if (g.objtype == mjOBJ_GEOM && rbound > 0.0 && g.type != mjGEOM_PLANE && g.type != mjGEOM_HFIELD) {
      const double r = 1.02 * rbound + 0.01;
      const Eigen::Vector3d c = R_W_C.transpose() * (Eigen::Vector3d(g.pos[0], g.pos[1], g.pos[2]) - p_W);
      // Side planes through the optical centre, x = +-tan_x z and y = +-tan_y z; signed distance outwards.
      outside = c.z() + r < 0.0 || c.z() - r > zfar_m || (std::abs(c.x()) - tan_x * c.z()) * nx > r ||
                (std::abs(c.y()) - tan_y * c.z()) * ny > r;
    }
    if (!outside) scene.geoms[kept++] = g;
  }
  const int culled = scene.ngeom - kept;
  scene.ngeom = kept;
  return culled;
}

}  // namespace

ThrowOnMujocoError::ThrowOnMujocoError() {
  std::lock_guard<std::mutex> lock(hook_mutex());
  if (hook_depth++ == 0) {
    hook_previous = mju_user_error;
    mju_user_error = &raise;
  }
}

ThrowOnMujocoError::~ThrowOnMujocoError() {
  std::lock_guard<std::mutex> lock(hook_mutex());
  if (--hook_depth == 0) mju_user_error = hook_previous;
}

MujocoScene::MujocoScene(const mjModel* model, const CameraIntrinsics& k, GlBackend backend,
                         const std::array<bool, 6>& visible_geom_groups, const std::string& owner_name)
    : owner(owner_name), intrinsics(k) {
  if (!model) throw std::invalid_argument(owner + ": model is null");
  k.validate();
  if (!k.square_pixels()) {
    throw std::invalid_argument(owner + ": fx " + std::to_string(k.fx) + " != fy " + std::to_string(k.fy) +
                                ": MuJoCo 2.2.2 renders square pixels only (use fx = fy)");
  }
  ngeom = model->ngeom;
  nmesh = model->nmesh;
  znear_m = std::min(0.05, 0.5 * k.min_range_m);
  zfar_m = 2.0 * k.max_range_m + 1.0;
  gl = GlContext::create(backend);
  set_depth_only_option(option, visible_geom_groups);
  mjv_defaultCamera(&camera);

  ThrowOnMujocoError guard;
  mjv_defaultScene(&scene);
  mjv_makeScene(model, &scene, model->ngeom + 64);
  scene_made = true;
  set_segmentation_flags(scene);
  make_render_context(model, k, owner, context);
  context_made = true;
  mjr_setBuffer(mjFB_OFFSCREEN, &context);
  if (context.currentBuffer != mjFB_OFFSCREEN || context.offWidth < k.width || context.offHeight < k.height) {
    throw std::runtime_error(owner + ": " + std::string(to_string(gl->backend())) + " offscreen framebuffer " +
                             std::to_string(context.offWidth) + "x" + std::to_string(context.offHeight) +
                             " unavailable or smaller than needed " + std::to_string(k.width) + "x" +
                             std::to_string(k.height));
  }
}

MujocoScene::~MujocoScene() {
  if (gl) {
    try {
      gl->make_current();
    } catch (const std::exception&) {
    }
  }
  if (context_made) mjr_freeContext(&context);
  if (scene_made) mjv_freeScene(&scene);
}

void MujocoScene::update(const mjModel* model, mjData* data, const Eigen::Isometry3d& T_world_camera) {
  if (!model || !data) throw std::invalid_argument(owner + "::render: model or data is null");
  if (model->ngeom != ngeom || model->nmesh != nmesh) {
    throw std::invalid_argument(owner + "::render: model has " + std::to_string(model->ngeom) + " geoms, " +
                                std::to_string(model->nmesh) + " meshes; the renderer was made for " +
                                std::to_string(ngeom) + ", " + std::to_string(nmesh));
  }
  const Eigen::Matrix3d R = T_world_camera.linear();
  const Eigen::Vector3d p = T_world_camera.translation();
  if (!R.allFinite() || !p.allFinite() ||
      (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 || R.determinant() < 0.0) {
    throw std::invalid_argument(owner + "::render: T_world_camera is not a finite rigid transform");
  }
  ThrowOnMujocoError guard;  // no GL here: the scene is CPU work, the context may be drawing on another thread
  mjv_updateScene(model, data, &option, nullptr, &camera, mjCAT_STATIC | mjCAT_DYNAMIC, &scene);

  // Override the GL camera: OpenGL eye looks along -z_eye = +z optical, with y_eye up = -y optical.
  // Frustum at the near plane n (pixel centres at integer u, v; GL rows bottom first):
  //   top = n (cy + 1/2) / fy, bottom = -n (H - cy - 1/2) / fy, centre = n (W/2 - cx - 1/2) / fx.
  // MuJoCo sets the half width from the viewport aspect: 0.5 W/H (top - bottom) = 0.5 W n / fy (square pixels).
  const CameraIntrinsics& k = intrinsics;
  const double n = znear_m;
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
  gl_camera.frustum_far = float(zfar_m);
  scene.camera[0] = gl_camera;
  scene.camera[1] = gl_camera;
  scene.enabletransform = 0;
  culled_geoms = 0;
  if (cull_outside_view) {
    const double tan_x = 1.02 * std::max(k.cx + 0.5, k.width - 0.5 - k.cx) / k.fx;
    const double tan_y = 1.02 * std::max(k.cy + 0.5, k.height - 0.5 - k.cy) / k.fy;
    culled_geoms = cull_geoms_outside_view(scene, R, p, tan_x, tan_y, zfar_m);
  }
}

}  // namespace stvl::sensors

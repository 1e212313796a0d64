#pragma once
// What a depth camera needs of MuJoCo's renderer, shared by DepthRenderer and its reference twin (which differ
// only in how they read the depth back): the GL context, a scene in segmentation mode showing the chosen geom
// groups, a rendering context made from a copy of the model (MSAA off, the offscreen buffer as large as the image,
// finer sphere and cylinder tessellation, planes as 2 x 2 grids), and the GL camera of pinhole intrinsics.
#include <mujoco/mujoco.h>

#include <Eigen/Geometry>

#include <array>
#include <memory>
#include <string>

#include "sensors/camera.hpp"
#include "sensors/gl_context.hpp"

namespace stvl::sensors {

// While alive, MuJoCo's fatal errors (mju_user_error: print and exit) are thrown as std::runtime_error; libmujoco
// has unwind tables, so they pass through its C frames. The hook is one global: with guards on several threads,
// the first installs it and the last restores it.
class ThrowOnMujocoError {
 public:
  ThrowOnMujocoError();
  ~ThrowOnMujocoError();
  ThrowOnMujocoError(const ThrowOnMujocoError&) = delete;
  ThrowOnMujocoError& operator=(const ThrowOnMujocoError&) = delete;
};

struct MujocoScene {
  // As DepthRenderer's constructor; `owner` names the caller in error messages. GL near plane at
  // min(0.05, min_range / 2) (closer geometry still occludes and reads invalid), far plane at 2 max_range + 1 m.
  MujocoScene(const mjModel* model, const CameraIntrinsics& intrinsics, GlBackend backend,
              const std::array<bool, 6>& visible_geom_groups, const std::string& owner);
  // Frees the rendering context and the scene with the GL context current.
  ~MujocoScene();
  MujocoScene(const MujocoScene&) = delete;
  MujocoScene& operator=(const MujocoScene&) = delete;

  // Checks model (the geoms and meshes it was made for), data and T_world_camera (a finite rigid transform; the
  // optical frame in the world) and updates the scene, its camera the intrinsics' frustum at that pose. Makes no
  // GL call, so it may run on any thread while the context is current on another (DepthRenderer::prepare).
  // Throws std::invalid_argument (naming owner::render), std::runtime_error from MuJoCo.
  void update(const mjModel* model, mjData* data, const Eigen::Isometry3d& T_world_camera);

  // When set, update() leaves out of the scene every geom whose bounding sphere (the model's rbound) lies wholly
  // outside the camera's view (behind it, beyond the far plane, or past a side of the image with a margin): GL
  // clips such a geom to nothing, so every depth value stays what it was, at less vertex work. Planes and height
  // fields (no finite bound) always stay. Off in the reference twin, which the tests compare with.
  bool cull_outside_view = false;
  int culled_geoms = 0;  // how many the last update() left out

  std::string owner;
  CameraIntrinsics intrinsics;
  std::unique_ptr<GlContext> gl;
  mjvScene scene{};
  mjrContext context{};
  mjvOption option{};
  mjvCamera camera{};
  bool scene_made = false, context_made = false;
  int ngeom = 0, nmesh = 0;
  double znear_m = 0.0, zfar_m = 0.0;
};

}  // namespace stvl::sensors

#pragma once
// Off-screen metric depth rendering of a MuJoCo 2.2.2 scene from any optical-frame pose.
#include "sensors/camera.hpp"
#include "sensors/depth_image.hpp"
#include "sensors/gl_context.hpp"

#include <mujoco/mujoco.h>

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

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

  // render() in two halves, for render_concurrently(): prepare() checks the input and updates the scene from
  // model and data (MuJoCo's side; one renderer at a time); draw() renders the prepared scene and converts it, on
  // any thread, concurrently with other renderers' draw(); release_context() leaves the calling thread without
  // this renderer's GL context (so that another thread may take it). Throws as render().
  void prepare(const mjModel* model, mjData* data, const Eigen::Isometry3d& T_world_camera);
  const DepthImage& draw();
  void release_context();
  const DepthImage& image() const;  // the last image drawn (render(), draw() or render_concurrently())

  const CameraIntrinsics& intrinsics() const;
  GlBackend backend() const;
  const char* backend_name() const;  // "egl" or "osmesa"
  double znear_m() const;            // GL near plane: geometry closer than this is not drawn
  // Geoms the last prepare() left out of the scene: wholly outside the view, so GL would have clipped them to
  // nothing (MujocoScene::cull_outside_view; the image is the same, tests compare it with the reference).
  int culled_geoms() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// One image row from glReadPixels(GL_DEPTH_STENCIL, GL_UNSIGNED_INT_24_8) words (24-bit depth << 8 | stencil) to
// metres along the optical axis for a GL frustum near_m .. far_m (as floats GL was given): Mesa's float depth
// (z24 / 0xffffff in double, rounded to float), then z = near / (1 - d (1 - near / far)) in double; 0 where d = 1
// or z lies outside [min_m, max_m] (or is not finite). count values each; what the renderer runs on every row.
void depth_m_from_z24s8(const std::uint32_t* z24s8, float* depth_m, int count, double near_m, double far_m, float min_m,
                        float max_m);

// renderers[i]->render(model, data, T_world_camera[i]) for every i, the images the same as one after another:
// the scenes are updated in turn on the calling thread, then each renderer draws on its own thread (the first on
// the calling one). The renderers must be distinct; the sizes must match (std::invalid_argument). The first
// exception of any renderer is rethrown once all have finished.
void render_concurrently(const std::vector<DepthRenderer*>& renderers, const mjModel* model, mjData* data,
                         const std::vector<Eigen::Isometry3d>& T_world_camera);

}  // namespace stvl::sensors

#pragma once
// Occluded obstacles erased (STVL issue #134): true voxels that an update's clearing removed while the noise-free
// camera did not see them in that frame (behind a nearer surface, or out of its view). STVL's frustum acceleration
// decays every voxel inside the frustum, seen or hidden; ray-cast clearing only clears up to each point.
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "common/voxel_key.hpp"
#include "sensors/camera.hpp"
#include "sensors/depth_image.hpp"
#include "truth/ground_truth.hpp"

namespace stvl::evaluation {

enum class VoxelSight { kSeen, kBehindSurface, kOutOfView };

// What the noise-free camera saw of the voxel `key` (edge voxel_size_m). Its centre and its 8 corners are the
// samples; a sample's pixel is the nearest one to its projection. Seen: some sample projects into the image on a
// pixel whose depth is valid and not nearer than the sample's by more than tolerance_m. Else behind a surface:
// some sample's pixel holds a nearer depth. Else out of view: every sample lies behind the camera, outside the
// image or on a pixel without a return.
VoxelSight voxel_sight(const VoxelKey& key, double voxel_size_m, const sensors::DepthImage& clean_depth,
                       const sensors::CameraIntrinsics& intrinsics, const Eigen::Isometry3d& T_world_camera,
                       double tolerance_m);

struct OcclusionBody {
  std::string name;
  std::size_t hidden_false_clears = 0;
  double first_s = 0, last_s = 0;  // the first and the last update that removed one of its voxels unseen
  // The first such update after which none of the body's truth voxels was in the map: the obstacle erased.
  std::optional<double> vanished_s;
};

struct OcclusionResult {
  // Truth voxels (static, or of a moving body where it is now) that an update's clearing removed (cleared_keys:
  // rays or frustum acceleration, not plain expiry), that the same update did not mark again, and that the
  // noise-free camera did not see in that frame; summed over the updates.
  std::size_t hidden_false_clears = 0;
  std::size_t behind_surface = 0, out_of_view = 0;  // hidden_false_clears by voxel_sight()
  std::optional<double> first_s;                    // the first update with one
  std::vector<OcclusionBody> bodies;                // every body with one, sorted by name
};

class HiddenClears {
 public:
  // One update at time_s. cleared: the voxels its clearing removed. bodies: the truth bodies now; body_of(key):
  // the index in bodies of the one holding key, -1 for none; in_map(key): the map holds key after the update;
  // sight(key): what the camera saw of it in this frame.
  void after_update(double time_s, const std::vector<VoxelKey>& cleared,
                    const std::vector<const truth::BodyVoxels*>& bodies,
                    const std::function<int(const VoxelKey&)>& body_of,
                    const std::function<bool(const VoxelKey&)>& in_map,
                    const std::function<VoxelSight(const VoxelKey&)>& sight);
  // The totals over every update so far, with the bodies sorted by name.
  OcclusionResult result() const;

 private:
  struct Entry {
    OcclusionBody body;
    std::size_t hint = 0;  // index of the body's voxel last found in the map (likely still there)
  };
  OcclusionResult totals_;
  std::map<std::string, Entry> bodies_;
};

}  // namespace stvl::evaluation

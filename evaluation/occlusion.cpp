#include "evaluation/occlusion.hpp"

#include <algorithm>
#include <cmath>

namespace stvl::evaluation {

VoxelSight voxel_sight(const VoxelKey& key, double voxel_size_m, const sensors::DepthImage& clean_depth,
                       const sensors::CameraIntrinsics& intrinsics, const Eigen::Isometry3d& T_world_camera,
                       double tolerance_m) {
  const Eigen::Isometry3d T_camera_world = T_world_camera.inverse();
  const Eigen::Vector3d lo_W = Eigen::Vector3d(key.x, key.y, key.z) * voxel_size_m;
  bool behind = false;
  for (int sample = 0; sample < 9; ++sample) {
    // Sample 0 is the centre, 1..8 the corners.
    const Eigen::Vector3d offset =
        sample == 0 ? Eigen::Vector3d(0.5, 0.5, 0.5)
                    : Eigen::Vector3d((sample - 1) & 1, ((sample - 1) >> 1) & 1, ((sample - 1) >> 2) & 1);
    const Eigen::Vector3d p_C = T_camera_world * (lo_W + offset * voxel_size_m);
    const auto pixel = sensors::project_to_pixel(intrinsics, p_C);
    if (!pixel) continue;
    const long u = std::lround(pixel->x()), v = std::lround(pixel->y());
    if (u < 0 || v < 0 || u >= clean_depth.width || v >= clean_depth.height) continue;
    const float z = clean_depth.at(static_cast<int>(u), static_cast<int>(v));
    if (!(z > 0.0f)) continue;
    if (z >= p_C.z() - tolerance_m) return VoxelSight::kSeen;
    behind = true;
  }
  return behind ? VoxelSight::kBehindSurface : VoxelSight::kOutOfView;
}

void HiddenClears::after_update(double time_s, const std::vector<VoxelKey>& cleared,
                                const std::vector<const truth::BodyVoxels*>& bodies,
                                const std::function<int(const VoxelKey&)>& body_of,
                                const std::function<bool(const VoxelKey&)>& in_map,
                                const std::function<VoxelSight(const VoxelKey&)>& sight) {
  std::vector<int> hit;
  for (const VoxelKey& k : cleared) {
    const int b = body_of(k);
    if (b < 0 || in_map(k)) continue;
    const VoxelSight s = sight(k);
    if (s == VoxelSight::kSeen) continue;
    ++totals_.hidden_false_clears;
    ++(s == VoxelSight::kBehindSurface ? totals_.behind_surface : totals_.out_of_view);
    if (!totals_.first_s) totals_.first_s = time_s;
    OcclusionBody& body = bodies_[bodies[static_cast<std::size_t>(b)]->body_name].body;
    if (body.hidden_false_clears++ == 0)
      body.name = bodies[static_cast<std::size_t>(b)]->body_name, body.first_s = time_s;
    body.last_s = time_s;
    hit.push_back(b);
  }
  std::sort(hit.begin(), hit.end());
  hit.erase(std::unique(hit.begin(), hit.end()), hit.end());
  // Is any of the body's truth voxels left in the map? Start at the one found last time.
  for (const int b : hit) {
    const std::vector<VoxelKey>& voxels = bodies[static_cast<std::size_t>(b)]->voxels;
    Entry& entry = bodies_[bodies[static_cast<std::size_t>(b)]->body_name];
    if (entry.body.vanished_s) continue;
    bool left = false;
    for (std::size_t i = 0; i < voxels.size() && !left; ++i) {
      const std::size_t j = (entry.hint + i) % voxels.size();
      if (in_map(voxels[j])) left = true, entry.hint = j;
    }
    if (!left) entry.body.vanished_s = time_s;
  }
}

OcclusionResult HiddenClears::result() const {
  OcclusionResult r = totals_;
  for (const auto& [name, entry] : bodies_) r.bodies.push_back(entry.body);
  return r;
}

}  // namespace stvl::evaluation

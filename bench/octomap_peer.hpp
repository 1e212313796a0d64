#pragma once
// OctoMap's OcTree::insertPointCloud as the map benchmark's peer, built only when liboctomap was found at build
// time (STVL_HAVE_OCTOMAP).
#include <Eigen/Core>

#include <memory>

namespace stvl::bench {

class OctomapPeer {
 public:
  static bool available();
  // A fresh, empty OcTree of voxel_size_m. Throws std::runtime_error when built without OctoMap.
  explicit OctomapPeer(double voxel_size_m);
  ~OctomapPeer();
  OctomapPeer(const OctomapPeer&) = delete;
  OctomapPeer& operator=(const OctomapPeer&) = delete;

  // Wall time in ms of one insertPointCloud of points_W (world frame) seen from origin_W, rays cut at
  // max_range_m; the copy into OctoMap's cloud type is not timed.
  double insert_ms(const Eigen::Matrix3Xf& points_W, const Eigen::Vector3d& origin_W, double max_range_m);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace stvl::bench

#include "bench/octomap_peer.hpp"

#include <stdexcept>

#include "bench/timing.hpp"

#ifdef STVL_HAVE_OCTOMAP
#include <octomap/octomap.h>
#endif

namespace stvl::bench {

#ifdef STVL_HAVE_OCTOMAP
struct OctomapPeer::Impl {
  explicit Impl(double voxel_size_m) : tree(voxel_size_m) {}
  octomap::OcTree tree;
};

bool OctomapPeer::available() { return true; }

OctomapPeer::OctomapPeer(double voxel_size_m) : impl_(std::make_unique<Impl>(voxel_size_m)) {}

double OctomapPeer::insert_ms(const Eigen::Matrix3Xf& points_W, const Eigen::Vector3d& origin_W, double max_range_m) {
  octomap::Pointcloud cloud;
  cloud.reserve(static_cast<std::size_t>(points_W.cols()));
  for (Eigen::Index i = 0; i < points_W.cols(); ++i) cloud.push_back(points_W(0, i), points_W(1, i), points_W(2, i));
  const Eigen::Vector3f o = origin_W.cast<float>();
  return time_once_ms([&] { impl_->tree.insertPointCloud(cloud, octomap::point3d(o.x(), o.y(), o.z()), max_range_m); });
}
#else
struct OctomapPeer::Impl {};

bool OctomapPeer::available() { return false; }

OctomapPeer::OctomapPeer(double) {
  throw std::runtime_error(
      "OctoMap peer: stvl-bench was built without liboctomap (install liboctomap-dev and rebuild)");
}

double OctomapPeer::insert_ms(const Eigen::Matrix3Xf&, const Eigen::Vector3d&, double) { return 0.0; }
#endif

OctomapPeer::~OctomapPeer() = default;

}  // namespace stvl::bench

#include "evaluation/map_view.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "common/splitmix.hpp"

namespace stvl::evaluation {
namespace {

// About max_points of `points`, chosen by a hash of their voxel keys (spread evenly over the map, unlike every
// k-th in key order, which leaves stripes) and the same in every run.
Eigen::Matrix3Xf thinned(const std::vector<VoxelKey>& keys, const std::vector<Eigen::Vector3f>& points,
                         std::size_t max_points) {
  const std::uint64_t keep_per_1024 =
      points.size() <= max_points ? 1024 : std::max<std::uint64_t>(1, 1024 * max_points / points.size());
  std::vector<Eigen::Vector3f> kept;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (splitmix64_mix(VoxelKeyHash{}(keys[i])) % 1024 < keep_per_1024) kept.push_back(points[i]);
  Eigen::Matrix3Xf out(3, Eigen::Index(kept.size()));
  for (std::size_t c = 0; c < kept.size(); ++c) out.col(Eigen::Index(c)) = kept[c];
  return out;
}

}  // namespace

MapView make_map_view(const mapping::VoxelMap& map, const Truth& truth, int tolerance_voxels, std::size_t max_points) {
  MapView view;
  view.voxel_size_m = map.voxel_size_m();
  std::vector<Eigen::Vector3f> good, bad, truth_points;
  std::vector<VoxelKey> good_keys, bad_keys, truth_keys;
  for (const VoxelKey& key : map.voxel_keys()) {
    const bool near = truth.near(key, tolerance_voxels);
    (near ? good : bad).push_back(map.center_of(key).cast<float>());
    (near ? good_keys : bad_keys).push_back(key);
  }
  const Eigen::Matrix3Xf centers = truth.voxel_centers();
  for (Eigen::Index i = 0; i < centers.cols(); ++i) {
    truth_points.push_back(centers.col(i));
    truth_keys.push_back(voxel_key(centers.col(i).cast<double>(), view.voxel_size_m));
  }
  view.mapped_true = good.size(), view.mapped_false = bad.size(), view.truth = truth_points.size();
  view.mapped_true_W = thinned(good_keys, good, max_points);
  view.mapped_false_W = thinned(bad_keys, bad, max_points);
  view.truth_W = thinned(truth_keys, truth_points, max_points);
  return view;
}

MapView make_map_view(const mapping::VoxelMap& map, std::size_t max_points) {
  MapView view;
  view.voxel_size_m = map.voxel_size_m();
  std::vector<Eigen::Vector3f> points;
  const std::vector<VoxelKey> keys = map.voxel_keys();
  for (const VoxelKey& key : keys) points.push_back(map.center_of(key).cast<float>());
  view.unjudged = points.size();
  view.unjudged_W = thinned(keys, points, max_points);
  return view;
}

}  // namespace stvl::evaluation

#pragma once
// Private to mapping/: VoxelMap's state on OpenVDB. The only header that includes OpenVDB, included only by the
// voxel_map*.cpp files (core; decay and expiry; ray-cast clearing; .vdb/.ply I/O). Never include it from a public
// header: each file that does costs 10-20 s and 600 MB to compile.
#include <openvdb/openvdb.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <unordered_map>
#include <utility>
#include <variant>
#include <vector>

#include "mapping/frustum.hpp"
#include "mapping/lidar_frustum.hpp"
#include "mapping/voxel_map.hpp"

namespace stvl::mapping {
namespace detail {

using GridT = openvdb::DoubleGrid;
using TreeT = GridT::TreeType;
using LeafT = TreeT::LeafNodeType;
using Internal2T = TreeT::RootNodeType::ChildNodeType;
using Internal1T = Internal2T::ChildNodeType;
using openvdb::Coord;

constexpr double kBackground = 0.0;
constexpr double kMaxIndex = 1 << 30;  // keys beyond this are not representable; such points are skipped
constexpr const char* kGridName = "stvl_voxels";

inline Coord leaf_origin(const Coord& c) { return Coord(c.x() & ~7, c.y() & ~7, c.z() & ~7); }

// A clearing volume (the depth camera's frustum or STVL's 3D lidar model) with its source's decay acceleration.
struct Frustum {
  std::variant<DepthCameraFrustum, LidarFrustum> shape;
  double decay_acceleration_per_s3;
  bool contains(const Eigen::Vector3d& p_W) const {
    return std::visit([&](const auto& s) { return s.contains(p_W); }, shape);
  }
  bool may_intersect(const Eigen::AlignedBox3d& box_W) const {
    return std::visit([&](const auto& s) { return s.may_intersect(box_W); }, shape);
  }
};

void ensure_openvdb_initialized();  // voxel_map.cpp

}  // namespace detail

struct VoxelMap::Impl {
  using GridT = detail::GridT;
  using LeafT = detail::LeafT;
  using Coord = detail::Coord;

  StvlConfig config;
  GridT::Ptr grid;
  double latest_time_s = -std::numeric_limits<double>::infinity();
  // Expiry index (bounded walk, linear decay): every leaf holds an entry due no later than its oldest
  // voxel's expiry; `due_by_leaf` mirrors `due_queue` so an entry can be moved earlier.
  std::set<std::pair<double, Coord>> due_queue;
  std::unordered_map<Coord, double> due_by_leaf;
  // costmap_timing stvl: the voxels mark() created since the last clear(), per leaf origin as the leaf's value
  // mask words (word x, bit 8 y + z): STVL's costmap is built before its marks, so the projection leaves them out.
  std::unordered_map<Coord, std::array<std::uint64_t, 8>> created_since_clear;

  explicit Impl(const StvlConfig& map_config);

  bool uses_expiry_index() const {
    return config.clearing_walk == ClearingWalk::kBounded && config.decay_model == DecayModel::kLinear;
  }

  // ---- core (voxel_map.cpp)
  void check_time(double time_s);
  bool to_key(const Eigen::Vector3d& p_W, Coord& key) const {
    const Eigen::Vector3d scaled = (p_W / config.voxel_size_m).array().floor();
    if (!(scaled.cwiseAbs().maxCoeff() < detail::kMaxIndex)) return false;
    key = Coord(static_cast<int>(scaled.x()), static_cast<int>(scaled.y()), static_cast<int>(scaled.z()));
    return true;
  }
  // mark()'s key: to_key() (floor) or STVL's arithmetic (config.mark_rounding; see config.hpp).
  bool mark_key(const Eigen::Vector3d& p_W, Coord& key) const {
    if (config.mark_rounding == MarkRounding::kFloor) return to_key(p_W, key);
    const double vs = stvl_voxel_size_m(), inverse = 1.0 / vs;  // OpenVDB's ScaleMap multiplies by 1/vs
    const double x = p_W.x() < 0 ? p_W.x() - vs : p_W.x();
    const double y = p_W.y() < 0 ? p_W.y() - vs : p_W.y();
    const double z = p_W.y() < 0 ? p_W.z() - vs : p_W.z();  // STVL tests y's sign for z (ros2 403d9ed, noetic)
    const Eigen::Vector3d scaled(x * inverse, y * inverse, z * inverse);
    if (!(scaled.cwiseAbs().maxCoeff() < detail::kMaxIndex)) return false;
    // openvdb::Coord(Int32, Int32, Int32): the implicit conversion truncates toward zero.
    key = Coord(static_cast<int>(scaled.x()), static_cast<int>(scaled.y()), static_cast<int>(scaled.z()));
    return true;
  }
  // STVL's grid keeps voxel_size narrowed to float (the grid's constructor takes a float) in a double.
  double stvl_voxel_size_m() const { return static_cast<double>(static_cast<float>(config.voxel_size_m)); }
  Eigen::Vector3d centre_W(const Coord& key) const {
    return Eigen::Vector3d(key.x() + 0.5, key.y() + 0.5, key.z() + 0.5) * config.voxel_size_m;
  }
  // The point the frustum test takes for a voxel: centre_W, or with FrustumGeometry::kStvl STVL's IndexToWorld,
  // i*vs + vs/2 with vs = stvl_voxel_size_m(). Both are monotonic in the key, so the centres of a key box lie in
  // the box of its corner keys' centres (the bounded walk's culling relies on it).
  Eigen::Vector3d frustum_centre_W(const Coord& key) const {
    if (config.frustum_geometry != FrustumGeometry::kStvl) return centre_W(key);
    const double vs = stvl_voxel_size_m(), half = vs / 2.0;
    return Eigen::Vector3d(key.x() * vs + half, key.y() * vs + half, key.z() * vs + half);
  }

  // ---- decay and expiry (voxel_map_decay.cpp)
  // Defined here, not in the .cpp: it runs once per voxel in every walk and must inline.
  double base_time_left_s(double age_s) const {  // before frustum acceleration
    switch (config.decay_model) {
      case DecayModel::kLinear: return config.voxel_decay_s - age_s;
      case DecayModel::kExponential: return config.voxel_decay_s * std::exp(-age_s);
      case DecayModel::kPersistent: return config.voxel_decay_s;
    }
    return config.voxel_decay_s;
  }
  void schedule(const Coord& leaf, double due_s);
  void unschedule(const Coord& leaf);
  void rebuild_expiry_index();
  // Replaces empty leaves by inactive tiles, and internal nodes left without children likewise.
  void delete_empty_leaves(std::vector<Coord>& leaf_origins);
  // STVL's per-voxel rule. Returns true when the voxel is removed (then *by_frustum says whether the frustum's
  // acceleration removed it, i.e. it would have survived plain decay); otherwise may pull its value back.
  template <typename Iter>
  bool decay_voxel(Iter& it, const std::vector<detail::Frustum>& frustums, double time_s, double* new_value_s,
                   bool* by_frustum) const;
  // cleared_keys (may be null) receives the voxels the frustums' acceleration removed, removed_keys (may be null)
  // every voxel removed.
  void full_walk(const std::vector<detail::Frustum>& frustums, double time_s, ClearStats& stats,
                 std::vector<VoxelKey>* cleared_keys, std::vector<VoxelKey>* removed_keys);
  void frustum_pass(const std::vector<detail::Frustum>& frustums, double time_s, ClearStats& stats,
                    std::vector<VoxelKey>* cleared_keys, std::vector<VoxelKey>* removed_keys);
  void expiry_pass(double time_s, ClearStats& stats, std::vector<VoxelKey>* removed_keys);

  // ---- ray-cast clearing (voxel_map_raycast.cpp)
  void raycast_pass(const std::vector<ClearingObservation>& observations, ClearStats& stats,
                    std::vector<VoxelKey>* cleared_keys);
};

}  // namespace stvl::mapping

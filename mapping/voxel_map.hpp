#pragma once
// Spatio-temporal voxel map (STVL on OpenVDB). The value of a voxel is the time it was last marked
// (possibly pulled back by frustum acceleration, as STVL does); empty voxels are absent.
//
// Voxel index: key = floor(p / voxel_size) per axis, so voxel key k spans [k*s, (k+1)*s) and its centre is
// (k + 0.5)*s; negative coordinates work (p = -0.01 -> key -1). mark() uses config.mark_rounding instead (floor,
// or STVL's shifted truncation: mark_key_of()); lookup() and key_of() always floor. With
// config.frustum_geometry = kStvl the frustum test takes STVL's centre k*vs + vs/2, vs = double(float(s)).
//
// Clearing (one call to clear() per update, before mark(), as STVL's layer does), with age = time_s - value:
//   time_left = voxel_decay - age            (linear)
//             = voxel_decay * exp(-age)      (exponential: never below 0, so only frustums remove voxels)
//             = voxel_decay                  (persistent: likewise)
//   inside a clearing frustum time_left -= decay_acceleration * age^3 / 6, and if the voxel survives its value
//   is pulled back by that amount (STVL's compounding); a voxel with time_left < 0 is removed.
// Bounded walk: frustums visit only the leaf nodes (8^3 voxels) whose boxes meet them; linear expiry
// elsewhere comes from a per-leaf expiry index, at most expiry_leaves_per_update leaves per call. After
// ceil(backlog / expiry_leaves_per_update) further calls the map equals the full walk's.
// Ray-cast mode: instead of frustum acceleration, every voxel the ray walk (mapping/ray_walk.hpp) visits from
// the optical centre's voxel up to, not including, a point's voxel (rays cut at max_z) is removed at once;
// linear expiry still applies.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/voxel_key.hpp"
#include "mapping/config.hpp"
#include "mapping/costmap.hpp"

namespace stvl::mapping {

struct ClearingObservation {
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();  // optical frame
  ObservationSource source;
  const Eigen::Matrix3Xf* points_W = nullptr;  // required in ray-cast mode; must outlive the clear() call
  // With source.clear_on_no_return (ray-cast mode only): one point per ray of the pixels that returned nothing,
  // at max_z along it; walked as points_W are. Null: none.
  const Eigen::Matrix3Xf* no_return_W = nullptr;
};

struct Voxel {
  VoxelKey key;
  double time_s;
};

struct ClearStats {
  std::size_t voxels_visited = 0;  // voxels tested against frustums / rays / expiry
  std::size_t voxels_removed = 0;
  std::size_t leaves_visited = 0;
  std::size_t expiry_backlog = 0;  // leaves due for expiry but left for later calls (bounded walk)
};

class VoxelMap {
 public:
  explicit VoxelMap(const StvlConfig& config = {});  // throws std::invalid_argument
  ~VoxelMap();
  VoxelMap(VoxelMap&&) noexcept;
  VoxelMap& operator=(VoxelMap&&) noexcept;
  VoxelMap(const VoxelMap&) = delete;
  VoxelMap& operator=(const VoxelMap&) = delete;

  const StvlConfig& config() const;
  double voxel_size_m() const;

  // Marks points_W at time_s (no-op when !source.marking). Skips non-finite points, points farther than
  // obstacle_range (or closer than 1 cm) from the optical centre, and points outside the height band (world z;
  // a source whose band is in base_link, z_reference, gets none here: its buffer cloud was banded there).
  // Returns the number of points marked. Throws std::invalid_argument for a bad source, pose or time
  // (time_s must be finite and not earlier than any time already given to the map).
  std::size_t mark(const Eigen::Matrix3Xf& points_W, const Eigen::Isometry3d& T_world_camera,
                   const ObservationSource& source, double time_s);

  // Decay + clearing for one update at time_s. Observations with source.clearing == false are ignored.
  // cleared_keys, when given, receives the voxels the clearing removed: those the rays removed (ray-cast mode)
  // or the frustums' decay_acceleration removed (frustum mode: voxels plain decay would have kept), never those
  // that expired by plain decay, in no particular order. Throws std::invalid_argument for clear_on_no_return in
  // frustum mode. removed_keys, when given, receives every voxel the call removed, by the rays, the frustums or
  // plain decay (STVL's cleared_cells).
  ClearStats clear(const std::vector<ClearingObservation>& observations, double time_s,
                   std::vector<VoxelKey>* cleared_keys = nullptr, std::vector<VoxelKey>* removed_keys = nullptr);

  std::size_t size() const;  // active voxels
  bool empty() const { return size() == 0; }
  std::optional<double> lookup(const Eigen::Vector3d& p_W) const;  // time of the voxel holding p_W
  bool contains(const VoxelKey& key) const;                        // the voxel is in the map
  VoxelKey key_of(const Eigen::Vector3d& p_W) const;               // floor, whatever mark_rounding says
  VoxelKey mark_key_of(const Eigen::Vector3d& p_W) const;          // the key mark() gives p_W (config.mark_rounding)
  Eigen::Vector3d center_of(const VoxelKey& key) const;
  std::vector<VoxelKey> voxel_keys() const;  // sorted lexicographically (x, y, z)
  // Calls visit(key) for every voxel, in the tree's order (not sorted; cheaper than voxel_keys()).
  void for_each_key(const std::function<void(const VoxelKey&)>& visit) const;
  // Calls visit(key) for every voxel with lo <= key <= hi on each axis, in the tree's order (leaf by leaf);
  // leaves outside the box are skipped whole.
  void for_each_key_in(const VoxelKey& lo, const VoxelKey& hi, const std::function<void(const VoxelKey&)>& visit) const;
  // Calls visit(origin, on) for every leaf node (8^3 voxels) holding a voxel, in the tree's order: origin is its
  // lowest key (multiples of 8); bit b of on[w] is the voxel origin + (i >> 6, (i >> 3) & 7, i & 7), i = 64 w + b.
  // The same voxels as for_each_key(), a mask per leaf instead of a call per voxel (the evaluator's mirror).
  void for_each_leaf(const std::function<void(const VoxelKey& origin, const std::uint64_t* on)>& visit) const;
  // Calls visit(x, y, voxels) with a column's x, y keys and how many of its voxels have their centre z in
  // [min_z_m, max_z_m] (at least one), a leaf's 64 columns at a time (popcounts of its masks): a column spanning
  // several leaves comes once per leaf. With config.costmap_timing stvl, voxels that mark() created since the
  // last clear() are left out (STVL's costmap is built before its marks).
  void for_each_column(double min_z_m, double max_z_m,
                       const std::function<void(int x, int y, int voxels)>& visit) const;
  std::vector<Voxel> voxels() const;       // sorted by key
  Eigen::Matrix3Xf voxel_centers() const;  // in voxel_keys() order
  std::size_t leaf_count() const;
  // The bytes the voxel tree holds (OpenVDB's Tree::memUsage), the expiry index aside.
  std::size_t memory_bytes() const;

  // Inserts voxels directly (benchmarks, tests): key -> time.
  void set_voxels(const std::vector<Voxel>& voxels);
  // Removes these voxels where present; appends the removed ones to `erased` when given. Returns how many.
  std::size_t erase(const std::vector<VoxelKey>& keys, std::vector<VoxelKey>* erased = nullptr);

  // Column projection: lethal where a column holds >= max(mark_threshold, 1) voxels inside the band (counted as
  // for_each_column() counts them, so with costmap_timing stvl the last update's new voxels are not yet in it).
  Costmap2D project_costmap(const CostmapOptions& options = {}) const;

  // .vdb with one DoubleGrid "stvl_voxels" (world transform puts voxel centres at (k + 0.5)*s) and the
  // config as metadata; written to a temporary name and renamed. Throws std::runtime_error on I/O errors.
  void save_vdb(const std::string& path) const;
  static VoxelMap load_vdb(const std::string& path);
  // Binary little-endian PLY: float x, y, z (voxel centres), double time.
  void save_ply(const std::string& path) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace stvl::mapping

#pragma once
// Ground truth from the simulated geometry at the evaluation's voxel size: the surface voxels of every obstacle
// body inside the marking height band (truth::voxelize_bodies), the bodies' footprints, and which body holds a
// voxel. Static bodies are voxelized once; mocap (moving) bodies at their current poses on every update(). Lookups
// cache a leaf: one thread at a time.
#include <optional>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>

#include "common/voxel_key.hpp"
#include "evaluation/cell_grid.hpp"
#include "evaluation/config.hpp"
#include "evaluation/voxel_mask_set.hpp"
#include "truth/ground_truth.hpp"

namespace stvl::evaluation {

class Truth {
 public:
  // Static bodies voxelized once, moving ones at their poses in world now. Throws std::invalid_argument for a
  // bad config.
  Truth(const sim::World& world, const EvaluationConfig& config);
  // Moving bodies at their poses in `world` now (nothing is recomputed when none of them moved; a body that did
  // not move keeps its voxels).
  void update(const sim::World& world);
  // Increases whenever the truth changes (a moving body moved); the same version, the same truth.
  std::size_t version() const { return version_; }

  // Whether key is a truth voxel (of a static body, or of a moving one where it is now).
  bool contains(const VoxelKey& key) const;
  bool near(const VoxelKey& key, int tol) const;  // within tol voxels (Chebyshev) of a truth voxel
  // The two halves of near() at the config's tolerance_voxels: static bodies, and moving ones now (one lookup
  // in the moving bodies' voxels grown by the tolerance).
  bool near_static(const VoxelKey& key) const;
  bool near_moving(const VoxelKey& key) const { return dynamic_near_.contains(key); }
  // Index into bodies() of the first body holding `key` (static bodies first), -1 when none does.
  int body_of(const VoxelKey& key) const;
  // Its two halves: body_of() is static_body_of() when that is >= 0 (never changes), else moving_body_of().
  int static_body_of(const VoxelKey& key) const;
  int moving_body_of(const VoxelKey& key) const;
  // Static bodies, then moving ones; each with its voxels in the band.
  const std::vector<const truth::BodyVoxels*>& bodies() const { return bodies_; }
  // Whether the world has a mocap (moving) obstacle body.
  bool has_moving_bodies() const { return !dynamic_geoms_.empty(); }
  // Every voxel a moving body has occupied since the start, grown by one voxel: where stale map voxels can be.
  const VoxelSet& vacated() const { return vacated_; }
  // Whether key is in vacated() (a bit test where the last one was in the same 8^3 leaf).
  bool is_vacated(const VoxelKey& key) const { return vacated_mask_.contains(key); }
  // Appends to out the voxels whose place among vacated(), near_moving() or both may have changed since the last call
  // (repeats allowed): the ones newly vacated and the moving bodies' grown voxels before and after each update.
  void take_touched(std::vector<VoxelKey>& out) {
    out.insert(out.end(), touched_.begin(), touched_.end());
    touched_.clear();
  }
  // Footprint cells (cell = voxel size) of every body's solid in the band, now (kept until the truth changes).
  const CellGrid& footprint() const;
  // Distance from p_W to the nearest obstacle surface now; nullopt when there is no obstacle at all.
  std::optional<double> distance_to_surface_m(const Eigen::Vector3d& p_W) const;
  // The same for a voxel's centre. *fixed (when given) says whether no moving body can change it (no moving geom
  // in its search bucket and a hit within reach): then it holds for every later version in which
  // moving_distance_in() is false around the voxel (MappedIndex keeps such values). Reads only: safe to call from
  // several threads while nothing updates the truth.
  std::optional<double> voxel_distance_to_surface_m(const VoxelKey& key, bool* fixed = nullptr) const;
  // Whether a moving geom is in the distance search of a voxel centre in lo..hi (keys, each axis) now.
  bool moving_distance_in(const VoxelKey& lo, const VoxelKey& hi) const;
  // x/y extent of every obstacle now.
  Eigen::AlignedBox2d bounds_W() const;
  // What the truth could not make exact (truth::truth_notes(), each printed once to stderr when first met), and
  // what it is made of: obstacle geoms, of them meshes (mesh assets, height fields, finite planes), their triangles.
  const std::vector<truth::TruthNote>& notes() const { return notes_; }
  std::size_t geom_count() const { return geoms_.size(); }
  std::size_t mesh_geom_count() const;
  std::size_t mesh_triangle_count() const;
  // Truth voxel centres, sorted by key.
  Eigen::Matrix3Xf voxel_centers() const;

 private:
  void index_geoms();  // the buckets distance_to_surface_m() searches
  bool near_static_mask(const VoxelKey& key, int tol) const;

  EvaluationConfig config_;
  std::vector<truth::TruthNote> notes_;
  std::vector<truth::ObstacleGeom> geoms_;          // every obstacle geom, current poses
  std::vector<truth::ObstacleGeom> dynamic_geoms_;  // those of mocap bodies
  std::vector<truth::BodyVoxels> static_bodies_, dynamic_bodies_;
  std::vector<const truth::BodyVoxels*> bodies_;
  VoxelMaskSet static_truth_;   // the static bodies' voxels labelled with their body (not thread-safe)
  VoxelMaskSet dynamic_truth_;  // the moving bodies' voxels labelled with their index in bodies_
  VoxelMaskSet dynamic_near_;   // dynamic_truth_ grown by tolerance_voxels
  CellGrid static_footprint_;
  mutable CellGrid footprint_;  // footprint() at footprint_version_
  mutable std::size_t footprint_version_ = 0;
  VoxelSet vacated_;               // in insertion order's iteration (sort_in_vacated_order() follows it)
  VoxelMaskSet vacated_mask_;      // vacated_'s keys again, for the quick test
  VoxelMaskSet vacated_done_;      // the moving bodies' voxels so far: their neighbours are all in vacated_
  bool poses_only_ = false;        // the obstacle geoms never change, only their poses (truth::refresh_poses())
  std::vector<VoxelKey> touched_;  // take_touched()'s, since its last call
  // Geoms bucketed by 1 m cells of their bounding boxes grown by kReach, so a distance tests a few geoms.
  struct Bucket {
    std::vector<int> geoms;  // in geom order
    bool has_moving = false;
  };
  std::optional<double> distance_in(const Bucket* bucket, const Eigen::Vector3d& p_W, bool* fell_back) const;
  std::unordered_map<CellKey, Bucket, CellKeyHash> geoms_near_;
  std::vector<Eigen::AlignedBox3d> boxes_;
  std::size_t version_ = 0;
};

}  // namespace stvl::evaluation

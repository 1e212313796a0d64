#pragma once
// Map versus ground truth over a run, at the map's voxel size (see metrics.hpp for each figure):
//   every frame   observe() what the noise-free camera saw (recall's denominator), observe_clearing() before
//                 the map's update and after_update() after it (clearing latency of moved bodies);
//   periodically  evaluate(): a snapshot of every figure against the truth of the world's current state;
//   at the end    finish(): the final snapshot, means, obstacles, surface distances, clearing.
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "evaluation/clearing.hpp"
#include "evaluation/config.hpp"
#include "evaluation/mapped_index.hpp"
#include "evaluation/metrics.hpp"
#include "evaluation/occlusion.hpp"
#include "evaluation/seen_voxels.hpp"
#include "evaluation/stale_candidates.hpp"
#include "evaluation/truth.hpp"
#include "mapping/voxel_map.hpp"
#include "sensors/camera.hpp"
#include "sensors/depth_image.hpp"

namespace stvl::evaluation {

// Recall over the truth voxels one camera saw within the recall window (the total's definition, per camera).
struct CameraRecall {
  std::size_t observed_truth_voxels = 0, matched_truth = 0;
  double recall = 0;
};

struct EvaluationSnapshot {
  double time_s = 0;
  std::size_t mapped_voxels = 0;
  std::size_t observed_truth_voxels = 0;
  std::size_t matched_mapped = 0;
  std::size_t matched_truth = 0;
  double precision = 0, recall = 0, f1 = 0, iou = 0;
  std::size_t lethal_cells = 0;
  double costmap_precision = 0, costmap_recall = 0;
  int phantom_obstacles = 0;
  std::vector<Phantom> phantoms;      // phantom_obstacles of them, sorted by position
  std::vector<CameraRecall> cameras;  // by camera index (config.cameras of them)
  ProjectionGuard projection;         // the costmap against the voxels it was projected from
  SelfMarking self_marking;           // lethal cells on the robot (config.robot_footprint_B; 0 without one)
  PathBlock path_block;               // lethal cells in truth-free space within config.path_corridor_m of the path
};

// Means over the snapshots after the first recall window (all of them when there is only one).
struct EvaluationMean {
  double time_s = 0;          // the end of the run
  std::size_t snapshots = 0;  // how many were averaged
  // Of those, how many had no observed truth voxel (the camera saw nothing within the recall window: open floor):
  // left out of the means of recall, F1 and IoU, which are undefined there; precision leaves out those with no
  // mapped voxel.
  std::size_t empty_snapshots = 0;
  std::size_t mapped_voxels = 0, observed_truth_voxels = 0, lethal_cells = 0;  // means, rounded down
  double precision = 0, recall = 0, f1 = 0, iou = 0, costmap_precision = 0, costmap_recall = 0;
  double phantom_obstacles = 0;       // mean
  int max_phantom_obstacles = 0;      // the most at one snapshot
  std::vector<double> camera_recall;  // mean recall per camera index
  // The projection guard's worst counts over every snapshot (warm-up included).
  std::size_t max_lethal_without_voxels = 0, max_columns_without_lethal = 0;
  // The most self-marking lethal cells at one snapshot (warm-up included): inside the footprint, in the ring,
  // both together.
  std::size_t max_self_inside = 0, max_self_ring = 0, max_self_lethal = 0;
  // The snapshot with the most lethal cells in truth-free space along the path (over every snapshot), and when.
  PathBlock max_path_block;
  double max_path_block_time_s = 0;
};

// What the truth is made of, and what it could not make exact (metrics.json evaluation.truth).
struct TruthSummary {
  std::size_t geoms = 0, mesh_geoms = 0, mesh_triangles = 0;
  std::vector<truth::TruthNote> notes;  // empty: every obstacle geom the cameras draw is exact (the floor aside)
};

struct EvaluationSummary {
  TruthSummary truth;
  // What the layer allows to judge (EvaluationConfig): 3D figures (false: no voxels, nav2's ObstacleLayer), the
  // projection guard (false: a costmap not projected from voxels, nav2's layers).
  bool voxels_3d = true, costmap_projected = true;
  std::vector<EvaluationSnapshot> snapshots;
  EvaluationMean mean;
  EvaluationSnapshot final;               // at the end of the run
  std::vector<ObstacleResult> obstacles;  // sorted by body name
  DistanceStats accuracy;                 // mapped voxel centre to the nearest true surface, all snapshots pooled
  ClearingResult clearing;
  std::size_t observed_off_truth_voxels = 0;  // noise-free hits outside every truth voxel (render vs geometry)
  // Truth voxels (static, or of a moving body where it is now) that ray-cast clearing removed and the same
  // update did not mark again, summed over the frames: obstacles the rays wrongly cleared (noisy rays through a
  // surface, no-return pixels in front of one).
  std::size_t false_clears = 0;
  // Occluded obstacles erased: true voxels the clearing removed while the camera did not see them (occlusion.hpp).
  OcclusionResult occlusion;
};

// Averages the snapshots as EvaluationMean says; warm_up_s is the recall window.
EvaluationMean mean_of(const std::vector<EvaluationSnapshot>& snapshots, double warm_up_s);

// One camera's noise-free view of a frame.
struct CameraView {
  const sensors::DepthImage* clean_depth = nullptr;  // rendered depth, no noise
  sensors::CameraIntrinsics intrinsics;
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();  // optical frame
  double obstacle_range_m = 2.5;  // the source's marking range: farther hits are not expected in the map
  std::size_t camera_index = 0;   // < config.cameras
};

// Top-down picture of the last evaluation: true footprints, lethal and true, lethal and false, observed
// footprint missed; cells of cell_m.
struct TopDown {
  Eigen::AlignedBox2d bounds_W;
  double cell_m = 0.05;
  std::vector<CellKey> truth, true_positive, false_positive, false_negative;
};

// Wall-clock milliseconds spent in each phase of the evaluation, summed over the run (profiling only: never
// part of a result that is compared).
struct PhaseTimes {
  double observe_ms = 0;   // observe(): the noise-free view, per frame
  double clearing_ms = 0;  // observe_clearing() and after_update(), per frame
  double truth_ms = 0;     // moving bodies re-voxelized (inside the two above and evaluate())
  double mapped_ms = 0;    // evaluate(): mapped voxels against truth, and their surface distances
  double observed_ms = 0;  // evaluate(): observed truth against the map, per body
  double costmap_ms = 0;   // evaluate(): projection (beside mapped and observed), footprints, 2D matching
  double phantoms_ms = 0;  // evaluate(): connected lethal groups
  std::size_t frames = 0, evaluations = 0;
};

class Evaluator {
 public:
  // Throws std::invalid_argument for a bad config.
  Evaluator(const sim::World& world, const EvaluationConfig& config);

  // What the camera's noise-free view sees this frame (recall's denominator, the truth voxels in range and band,
  // per camera too); frame_keys() holds them afterwards.
  void observe(double time_s, const CameraView& view);
  // The truth of the world's state now (moving bodies), without a frame: a frame lost on the way.
  void refresh_truth(const sim::World& world) {
    if (truth_.has_moving_bodies()) update_truth(world);
  }
  // Before the map's update: moved bodies' stale voxels the view now sees through (clearing latency starts).
  void observe_clearing(double time_s, const sim::World& world, const CameraView& view, const mapping::VoxelMap& map);
  // cleared_keys: the voxels the update's clearing removed (layer::UpdateReport::cleared_keys); false_clears
  // counts them in ray-cast mode only.
  void after_update(double time_s, const mapping::VoxelMap& map, const std::vector<VoxelKey>& cleared_keys = {});
  // After after_update(): the true voxels the update's clearing removed unseen by view's noise-free camera
  // (behind a nearer surface or out of view, to within one voxel; occlusion.hpp), in both clearing modes.
  void observe_hidden_clears(double time_s, const CameraView& view, const mapping::VoxelMap& map,
                             const std::vector<VoxelKey>& cleared_keys);

  // The layer's own costmap for the 2D scores, when the layer's costmap is not the projection of its voxels (nav2's
  // layers raytrace and mark cells themselves): its lethal cells are scored and the projection guard is not run.
  // Unset (STVL): the costmap is projected from the map's voxels at voxel_size_m.
  void set_layer_costmap(std::function<mapping::Costmap2D()> costmap) { layer_costmap_ = std::move(costmap); }
  // The robot's pose at the map's last update (the footprint's place for clearing and self-marking).
  void set_robot_pose(const Eigen::Isometry3d& T_world_base) { T_world_base_ = T_world_base; }
  // A snapshot of every figure against the truth of the world's current state (kept for the means).
  const EvaluationSnapshot& evaluate(double time_s, const sim::World& world, const mapping::VoxelMap& map);
  // The final snapshot, the means, obstacles, surface distances, clearing and occlusion results.
  EvaluationSummary finish(double time_s, const sim::World& world, const mapping::VoxelMap& map);

  // The top-down picture of the last evaluate() or finish().
  const TopDown& top_down() const { return top_down_; }
  // Wall-clock totals per phase so far (profiling only).
  const PhaseTimes& phase_times() const { return times_; }
  // The ground truth at the world's state of the last update.
  const Truth& truth() const { return truth_; }
  // The voxels the last observe() saw (noise-free, in range and band), sorted.
  const std::vector<VoxelKey>& frame_keys() const { return frame_keys_; }

 private:
  void update_truth(const sim::World& world);
  // evaluate(), step by step.
  VoxelMatches match_mapped_voxels(const mapping::VoxelMap& map);  // also pools the surface distances
  // These two read the map as match_mapped_voxels() last saw it (mapped_, the same map in evaluate()).
  VoxelMatches match_observed_truth(double time_s, std::vector<CellKey>& observed_cells);
  std::vector<CameraRecall> camera_recalls(double time_s, const VoxelMatches& total);
  // The lethal cells of the map's own costmap, and its voxels per column in the band.
  CellGrid project_lethal(const mapping::VoxelMap& map, CellGrid& columns);
  void score_costmap(const mapping::VoxelMap& map, const CellGrid& lethal, const CellGrid& columns,
                     const CellGrid& observed_cells, EvaluationSnapshot& snap);

  EvaluationConfig config_;
  std::function<mapping::Costmap2D()> layer_costmap_;
  Eigen::Isometry3d T_world_base_ = Eigen::Isometry3d::Identity();
  Truth truth_;
  std::map<std::string, ObstacleResult> obstacles_;
  int body_of(SeenVoxels::Entry& seen) const;  // truth_.body_of(key), the static half remembered
  SeenVoxels last_seen_;                       // observed truth candidates -> last time
  // The same per camera, when there are several (one camera's is last_seen_ itself).
  std::vector<SeenVoxels> last_seen_by_camera_;
  VoxelSet off_truth_keys_;
  std::vector<VoxelKey> frame_keys_;  // observe(): the voxels of one frame
  ClearingLatency clearing_;
  std::size_t false_clears_ = 0;
  HiddenClears hidden_clears_;
  StaleCandidates stale_;  // where stale map voxels can be
  MappedIndex mapped_;     // the mapped voxels' results and pooled distances (bounded by distinct values: #270)
  std::vector<EvaluationSnapshot> snapshots_;
  TopDown top_down_;
  std::size_t top_down_version_ = 0;  // the truth version of top_down_.truth (versions start at 1)
  PhaseTimes times_;
};

}  // namespace stvl::evaluation

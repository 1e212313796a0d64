#pragma once
// Map-versus-ground-truth evaluation at the map's voxel size.
//
// Truth is the simulated geometry (sim::voxelize_bodies, surface voxels, within the marking height band).
// "Observed" truth is what the noise-free camera saw: a truth voxel counts toward recall when a noise-free
// depth pixel (within obstacle_range) fell into it during the last recall_window_s.
//   precision  mapped voxels within tolerance_voxels (Chebyshev) of any truth voxel / mapped voxels
//   recall     observed truth voxels within tolerance_voxels of a mapped voxel / observed truth voxels
//   f1         2 P R / (P + R);  iou = matched truth / (observed truth + unmatched mapped)
// 2D: lethal costmap cells against the true footprints in the band (same tolerance, in cells); a phantom is an
// 8-connected component of lethal cells (at least phantom_min_cells) with no true footprint within
// phantom_clearance_m (0.10 m by default, the same distance at every voxel size).
// Clearing latency: a mapped voxel that no longer lies on any true surface (a moved body's old place) is "seen
// through" once the noise-free depth at its pixel lies beyond it; its latency runs until it leaves the map.
#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "mapping/voxel_map.hpp"
#include "sensors/camera.hpp"
#include "sensors/depth_image.hpp"
#include "sim/ground_truth.hpp"
#include "tools/scenario.hpp"

namespace stvl::tools {

// A phantom: where it lies (the mean of its cell centres, world frame) and how many cells it has.
struct Phantom {
  double x_m = 0, y_m = 0;
  std::size_t cells = 0;
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
  std::vector<Phantom> phantoms;  // phantom_obstacles of them, sorted by position
};

struct ObstacleResult {
  std::string name;
  std::size_t truth_voxels = 0;     // surface voxels in the height band
  std::size_t observed_voxels = 0;  // the most seen at one evaluation
  double best_recall = 0;           // the best fraction of its observed voxels in the map at one evaluation
  bool observed = false;
  bool detected = false;            // best_recall >= 0.5 once observed
};

struct DistanceStats {
  std::size_t count = 0;
  double mean_m = 0, median_m = 0, p90_m = 0, p99_m = 0, max_m = 0;
};

struct ClearingResult {
  std::size_t stale_voxels_seen_through = 0;
  std::size_t not_cleared = 0;     // seen through but still in the map at the end
  double max_latency_s = 0;        // includes voxels never cleared (counted until the end)
  double mean_latency_s = 0;
};

struct EvaluationSummary {
  std::vector<EvaluationSnapshot> snapshots;
  EvaluationSnapshot mean;   // averaged over the snapshots after the first recall window
  EvaluationSnapshot final;  // at the end of the run
  std::vector<ObstacleResult> obstacles;
  DistanceStats accuracy;    // mapped voxel centre to the nearest true surface, all snapshots pooled
  ClearingResult clearing;
  std::size_t observed_off_truth_voxels = 0;  // noise-free hits outside every truth voxel (render vs geometry)
};

class Evaluator {
 public:
  Evaluator(const sim::World& world, const Scenario& scenario);

  // Every frame, with the noise-free depth image and the camera pose it was rendered from: what was observed.
  void observe(double time_s, const sensors::DepthImage& clean_depth, const sensors::CameraIntrinsics& intrinsics,
               const Eigen::Isometry3d& T_world_camera);
  // Clearing latency of moved bodies: call before the map's update with this frame (the map as the last frame
  // left it), then after_update() once the map has been cleared and marked.
  void observe_clearing(double time_s, const sim::World& world, const sensors::DepthImage& clean_depth,
                        const sensors::CameraIntrinsics& intrinsics, const Eigen::Isometry3d& T_world_camera,
                        const mapping::VoxelMap& map);
  void after_update(double time_s, const mapping::VoxelMap& map);
  // Periodically (evaluation.evaluate_every_s): compares the map with the truth of the world's current state.
  const EvaluationSnapshot& evaluate(double time_s, const sim::World& world, const mapping::VoxelMap& map);
  EvaluationSummary finish(double time_s, const sim::World& world, const mapping::VoxelMap& map);

  // Top-down picture of the last evaluation: true footprint grey, lethal and true green, lethal and false red,
  // missed (observed footprint not lethal) blue; pixels per cell given.
  struct TopDown {
    Eigen::AlignedBox2d bounds_W;
    double cell_m = 0.05;
    std::vector<stvl::CellKey> truth, true_positive, false_positive, false_negative;
  };
  const TopDown& top_down() const { return top_down_; }
  // Centres of the true surface voxels in the height band, sorted (for the bag's /ground_truth/occupancy).
  Eigen::Matrix3Xf truth_voxel_centers() const;

 private:
  void refresh_truth(const sim::World& world);  // statics once, mocap bodies every call
  bool is_truth(const stvl::VoxelKey& k) const;
  bool near_truth(const stvl::VoxelKey& k) const;  // within tolerance_voxels

  const Scenario* scenario_;
  double voxel_m_;
  std::vector<sim::ObstacleGeom> geoms_;          // every obstacle geom, current poses
  std::vector<sim::ObstacleGeom> dynamic_geoms_;  // those of mocap bodies
  std::vector<sim::BodyVoxels> static_bodies_;    // voxelized once
  std::unordered_map<stvl::VoxelKey, int, stvl::VoxelKeyHash> static_body_of_;  // voxel -> its first static body
  stvl::CellSet static_footprint_;
  bool statics_voxelized_ = false;
  stvl::VoxelSet static_truth_, dynamic_truth_;
  std::vector<sim::BodyVoxels> dynamic_bodies_;
  std::map<std::string, ObstacleResult> obstacles_;
  std::unordered_map<stvl::VoxelKey, double, stvl::VoxelKeyHash> last_seen_;
  std::unordered_map<stvl::VoxelKey, double, stvl::VoxelKeyHash> seen_through_;  // stale voxel -> first time
  stvl::VoxelSet vacated_;         // every voxel a moving body has occupied (dilated by one)
  stvl::VoxelSet off_truth_keys_;
  std::vector<double> latencies_s_;
  std::vector<double> distances_m_;
  std::vector<EvaluationSnapshot> snapshots_;
  TopDown top_down_;
};

}  // namespace stvl::tools

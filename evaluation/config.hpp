#pragma once
// What the map is compared with and how. Lengths in metres, times in seconds of simulated time.
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace stvl::evaluation {

struct EvaluationConfig {
  // Taken from the map and its observation source (not YAML keys of their own): truth is voxelized at the
  // map's voxel size and kept inside the marking height band.
  double voxel_size_m = 0.05;
  double min_obstacle_height_m = 0.0;
  double max_obstacle_height_m = 3.0;
  std::size_t cameras = 1;  // recall is also reported per camera
  // The map's costmap counts every voxel of a column (STVL's); false: only those in the height band above (the
  // map's costmap_band: marking_band).
  bool costmap_every_voxel = true;
  // The layer keeps voxels (false: nav2's ObstacleLayer, cells only): the 3D figures and checks need them.
  bool layer_has_voxels = true;
  // The layer's costmap is the projection of its voxels (STVL's; false: nav2's layers raytrace and mark cells, so
  // the projection guard, costmap_ghosts, has nothing to compare).
  bool costmap_projected = true;
  // A source's marking range is nav2's obstacle_max_range (nav2's layers) instead of STVL's obstacle_range.
  bool nav2_marking_range = false;

  // YAML evaluation.*, same names.
  double recall_window_s = 2.0;   // recall counts truth voxels the noise-free camera saw this recently
  double evaluate_every_s = 1.0;  // cadence of the full comparison (snapshots)
  int tolerance_voxels = 1;       // a match lies within this many voxels (cells in 2D), Chebyshev
  int min_observed_voxels = 3;    // an obstacle counts as observed once this many of its voxels were seen
  int phantom_min_cells = 2;      // lethal components smaller than this are not called phantoms
  // A lethal component is a phantom when no true footprint cell centre lies within this distance of one of
  // its cell centres (Chebyshev, rounded up to whole cells). Metres, so that the meaning does not change
  // with the voxel size; 0.10 m is below a small robot's inflation radius.
  double phantom_clearance_m = 0.10;

  // The robot's footprint in base_link (the map's, mapping::StvlConfig::footprint_B) and whether the costmap
  // frees it (update_footprint_enabled): self-marking is counted in it and in a ring of self_ring_m around it.
  std::vector<Eigen::Vector2d> robot_footprint_B;
  bool footprint_clearing = false;
  double self_ring_m = 0.10;

  // The path the robot must drive (the scenario's waypoints, a looping one closed; world frame) and the half
  // width of the corridor around it (YAML evaluation.path_corridor_m): lethal cells with no true footprint within
  // tolerance whose centre lies this close to the path block the robot (issue 31: a floor marked lethal).
  // 0.35 m: the robot's shell radius (worlds/robot.xml, 0.225 m) plus 0.125 m, about a nav2 inflation radius.
  std::vector<Eigen::Vector2d> path_W;
  double path_corridor_m = 0.35;

  // Throws std::invalid_argument naming the field (by its YAML key) and value.
  void validate() const;
};

}  // namespace stvl::evaluation

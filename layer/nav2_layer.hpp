#pragma once
// nav2's VoxelLayer and ObstacleLayer as layers of the bench (map.layer_type nav2_voxel | nav2_obstacle), each in
// the costmap nav2 would run it in: nav2_costmap_2d's plugins/voxel_layer.cpp and plugins/obstacle_layer.cpp,
// src/observation_buffer.cpp, src/layered_costmap.cpp (updateMap) and src/costmap_layer.cpp (the combinations), at
// ros-navigation/navigation2 main a3a97043 = jazzy f4108e5 where they agree (see the nav2_*.hpp bricks for the few
// places they do not).
//
// A costmap cycle (Costmap2DROS::updateMap at update_frequency, or once per instant with frames when it is 0) at
// time t with the robot at its pose of the last observation: the master and the layer's grid roll to the robot by
// whole cells (the voxel layer moves its voxel columns with its cells, new ones unknown), updateBounds gathers the
// buffers at t (the voxel layer always gathers both lists, the obstacle layer its clearing buffers only while every
// marking buffer is current), raytraces every clearing observation, then marks every marking one, then touches the
// footprint; the master is reset inside the bounds touched and updateCosts frees the footprint in the layer's own
// grid (footprint_clearing_enabled) and combines it there (combination_method). Observations go into the buffers
// when they are delivered, with their header stamp (earlier with camera timing: the purge ages them from it): the
// decimated cloud in the world frame and the optical centre as origin; a buffer keeps the points of its source's
// [min_obstacle_height, max_obstacle_height].
//
// costmap() is the layer's own grid after its last cycle (the footprint freed), master() nav2's combined costmap;
// voxels() is the voxel layer's marked voxels as the bench's cubic voxels of map.voxel_size (= the resolution): each
// marked nav2 voxel gives the voxels of its column cell whose centre z lies in it (the one holding its centre when
// z_resolution is finer), so the 3D scores read nav2's grid; the obstacle layer has none (has_voxels() false).
#include <cstdint>
#include <memory>
#include <vector>

#include "layer/layer.hpp"
#include "layer/nav2_observation_buffer.hpp"
#include "layer/nav2_obstacle_layer.hpp"
#include "layer/nav2_voxel_grid.hpp"

namespace stvl::layer {

class Nav2Layer : public Layer {
 public:
  // config.type must be a nav2 layer. Throws std::invalid_argument naming the key for a bad config (z_voxels
  // above 16, a resolution of 0, ranges that are negative or not finite, a source neither marking nor clearing).
  explicit Nav2Layer(LayerConfig config);
  ~Nav2Layer() override;
  Nav2Layer(const Nav2Layer&) = delete;
  Nav2Layer& operator=(const Nav2Layer&) = delete;

  void update(std::shared_ptr<const Observation> observation, const std::vector<SensorNow>& sensors,
              UpdateReport& report) override;
  const mapping::VoxelMap& voxels() const override;
  bool has_voxels() const override { return config_.type == LayerType::kNav2Voxel; }
  bool costmap_needs_voxels() const override { return false; }
  std::size_t map_bytes() const override {
    return voxel_grid_.columns().size() * sizeof(std::uint32_t) + grid_.costs.size();
  }
  mapping::Costmap2D costmap() const override;
  void reset(double time_s) override;
  // isCurrent at a cycle at time_s: every buffer's (the obstacle layer's short-circuit gives the same answer).
  bool current(double time_s) const override;
  std::vector<SourceStatus> source_status(double until_s) const override;

  // The voxel layer's grid (empty for the obstacle layer) and the layer's own 2D grid, as the last cycle left them.
  const nav2::VoxelGrid& voxel_grid() const { return voxel_grid_; }
  const nav2::CellGrid& layer_grid() const { return grid_; }
  // Cycles run so far.
  std::size_t cycles() const { return cycles_; }

 private:
  struct Source;
  LayerConfig config_;
  nav2::CellGrid grid_;                    // the layer's costmap_ (its origin the master's)
  nav2::VoxelGrid voxel_grid_;             // the voxel layer's columns, size_x x size_y (0 x 0 for the obstacle layer)
  std::vector<Source> sources_;            // every sensor's sources, in order
  std::vector<std::size_t> first_source_;  // per sensor: its first source's index in sources_
  std::size_t next_tick_ = 0;
  std::size_t cycles_ = 0;
  Eigen::Isometry3d T_world_base_ = Eigen::Isometry3d::Identity();
  mutable mapping::VoxelMap view_;  // voxels(), rebuilt on demand
  mutable bool view_stale_ = true;
  std::vector<VoxelKey> last_keys_;  // the view's keys after the last cycle (the cleared keys of the next)

  // One costmap cycle at time_s (appended to report.updates).
  void run_cycle(double time_s, UpdateReport& report);
  // The readings a cycle at time_s gathered (source index, observation; a buffer in both lists twice) into
  // update.applied_readings, once each, and the re-applied ones into the report and the sources' status.
  void report_applied(const std::vector<std::pair<std::size_t, const nav2::Nav2Observation*>>& applied, double time_s,
                      LayerUpdate& update, UpdateReport& report);
  // LayeredCostmap::updateMap after updateBounds: the master reset inside the bounds, the footprint freed in the
  // layer's grid (updateCosts' setConvexPolygonCost, footprint_W empty: off) and the grid combined there.
  void update_costs(const nav2::Bounds& bounds, const std::vector<Eigen::Vector2d>& footprint_W);
  // The bench's bookkeeping: the voxels the cycle removed from the view (still inside the window) into
  // report.cleared_keys; the view is rebuilt on demand.
  void record_cleared_keys(UpdateReport& report);
  // updateOrigin of the layer's grid (and voxel columns) to the master's new origin.
  void roll_to(double origin_x_m, double origin_y_m);
  // The voxel layer's raytraceFreespace and marking (nav2_voxel_layer.cpp).
  void voxel_raytrace(const nav2::Nav2Observation& observation, nav2::Bounds& bounds);
  void voxel_mark(const nav2::Nav2Observation& observation, nav2::Bounds& bounds);
  // The bench's keys of the voxel layer's marked voxels, sorted.
  std::vector<VoxelKey> marked_keys() const;
};

}  // namespace stvl::layer

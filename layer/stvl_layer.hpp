#pragma once
// STVL's layer (spatio_temporal_voxel_layer, ros2 403d9ed = noetic 5e06daf for what follows): its sources'
// measurement buffers (source_buffer.hpp), its update clock, clearing then marking at each update, the footprint
// voxel clearing (clear_footprint_voxels_below; STVL has none) and the costmap it publishes, on the voxel map of
// mapping/. With map.nav2_costmap it feeds nav2's master costmap after every update.
//
// An update applies the buffers of the sensor whose observation it is and, as STVL applies every buffer at every
// update, those of sensors that have missed a frame (an outage): their last readings, at the pose they were taken
// from, cleared and marked again at this time, once per distinct update time. With map.update_grouping instant, an
// observation that another sensor's frame at the same time follows only buffers; the last of the instant updates
// with every sensor's reading of it. With map.update_frequency STVL updates at every tick k / f: the ticks since the
// last observation run first, at their own times, from the buffers as they were; the observation's own time
// updates only when it is a tick.
#include <memory>
#include <vector>

#include "layer/layer.hpp"

namespace stvl::layer {

class StvlLayer : public Layer {
 public:
  // Throws std::invalid_argument for a bad map or nav2_costmap config.
  explicit StvlLayer(LayerConfig config);
  ~StvlLayer() override;
  StvlLayer(const StvlLayer&) = delete;
  StvlLayer& operator=(const StvlLayer&) = delete;

  void update(std::shared_ptr<const Observation> observation, const std::vector<SensorNow>& sensors,
              UpdateReport& report) override;
  const mapping::VoxelMap& voxels() const override { return map_; }
  void reset(double time_s) override;
  std::size_t map_bytes() const override { return map_.memory_bytes(); }
  mapping::Costmap2D costmap() const override;
  std::vector<SourceStatus> source_status(double until_s) const override;
  const LayerConfig& config() const { return config_; }
  // Inserts voxels into the map directly, key -> time (benchmarks: a map of a given size before the first update).
  void set_voxels(const std::vector<mapping::Voxel>& voxels) { map_.set_voxels(voxels); }

  bool current(double time_s) const override;

 private:
  struct Sensor;
  LayerConfig config_;
  mapping::VoxelMap map_;
  std::vector<std::unique_ptr<Sensor>> sensors_;
  std::size_t next_tick_ = 0;  // with map.update_frequency_hz: the index k of the next update time k / f
  Eigen::Isometry3d T_world_base_ = Eigen::Isometry3d::Identity();  // the robot at the last observation

  // Whether the observation's own time runs an update now (grouping and the tick clock).
  bool updates_now(const Observation& observation, const std::vector<SensorNow>& sensors) const;
  // One update at time_s from the buffers (appended to report.updates; counted into the report).
  void run_update(double time_s, std::size_t sensor_index, const std::vector<SensorNow>& sensors, UpdateReport& report);
  // The buffered readings an update at time_s applies, clearing and marking, counted into the sources' status.
  struct Applied;
  Applied collect(double time_s, std::size_t sensor_index, const std::vector<SensorNow>& sensors, LayerUpdate& update,
                  UpdateReport& report);
  // The footprint voxel clearing after marking (clear_footprint_voxels_below).
  void clear_footprint_voxels(UpdateReport& report);
  // One nav2 cycle after an update at time_s: the layer on the window at the robot, the voxels it removed.
  void feed_master(double time_s, const std::vector<VoxelKey>& removed);
};

// The costmap's options: with map.costmap_band marking_band (the bench's) the sensors' marking band (STVL's
// every_voxel: no band) and, with map.update_footprint_enabled, the footprint at T_world_base freed (STVL's
// footprint clearing at the robot's pose of the last update).
mapping::CostmapOptions costmap_options(const LayerConfig& config, const Eigen::Isometry3d& T_world_base);

}  // namespace stvl::layer

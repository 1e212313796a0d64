#pragma once
// A costmap layer as nav2 sees one: fed the observations of its sensors, it keeps their buffers and its own update
// clock, updates its voxels (or cells) at its ticks, and gives its costmap as it would publish it. The frame loop
// (run/) calls update() once per observation; a layer calls nothing back.
//
//   auto layer = layer::make_layer(config);            // STVL's, or nav2's voxel or obstacle layer
//   layer::UpdateReport report;
//   layer->update(observation, sensors_now, report);  // per observation, in stamp order
//   layer->costmap();                                 // what it would publish now
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "common/voxel_key.hpp"
#include "layer/config.hpp"
#include "layer/nav2_costmap.hpp"
#include "layer/observation.hpp"
#include "layer/source_buffer.hpp"
#include "mapping/costmap.hpp"
#include "mapping/voxel_map.hpp"

namespace stvl::layer {

// One observation a layer update took: which sensor and source, and the buffered observation.
struct AppliedReading {
  std::size_t sensor_index = 0, source_index = 0;
  std::shared_ptr<const Observation> reading;
  // The cloud (world frame) the layer took from the reading when it is not STVL's (source_marking_W): nav2's
  // buffers keep the decimated cloud inside the source's height band. Null for STVL.
  std::shared_ptr<const Eigen::Matrix3Xf> cloud_W;
};

// One update of the layer: its time and every reading it took, in the order STVL's layer takes them (sensors in
// order, each sensor's sources in order, each buffer newest first).
struct LayerUpdate {
  double time_s = 0;
  std::vector<AppliedReading> applied_readings;
};

// What one observation made the layer do.
struct UpdateReport {
  // The updates it ran, in time order: with update_frequency the ticks since the last observation (earlier than its
  // stamp), then the one at its stamp when that is a tick; otherwise at most one, at its stamp. Empty when the
  // observation only went into the buffers (another sensor's frame of the same instant follows, or the next tick
  // is later).
  std::vector<LayerUpdate> updates;
  bool map_updated() const { return !updates.empty(); }
  // Voxels the updates' clearing removed: the rays (ray-cast mode) or the frustum's acceleration (frustum mode), and
  // those of the footprint voxel clearing; not those that expired by plain decay.
  std::vector<VoxelKey> cleared_keys;
  std::size_t footprint_voxels_cleared =
      0;  // voxels removed inside the robot's footprint (clear_footprint_voxels_below)
  // Readings of earlier frames the updates applied again from the buffers (observation_persistence, or a stopped
  // sensor's buffer, as STVL applies every buffer at every update).
  std::size_t reapplied_readings = 0;
  // Wall-clock milliseconds of clearing (with the buffering) and marking (with the footprint voxel clearing), and
  // the process's CPU milliseconds (all threads) over both.
  double clear_ms = 0, mark_ms = 0, cpu_ms = 0;
};

// One observation source's record over the run: when it was not current (STVL's expected_update_rate) and what its
// buffer applied again.
struct SourceStatus {
  std::string source;
  std::size_t camera_index = 0;
  double expected_update_rate_s = 0;
  std::vector<StaleSpan> stale;        // in time order; the last one may end at the time asked for (still stale)
  std::size_t reapplied_readings = 0;  // readings applied at a later update than their own frame's
  double max_reapplied_age_s = 0;      // the oldest of those at the update that applied it
  double reapplied_max_distance_m =
      0;  // farthest a re-applied reading's optical centre lay from the camera's pose then
};

class Layer {
 public:
  virtual ~Layer() = default;

  // Takes one observation (not null) at its stamp, with every sensor's state now (one per sensor): buffers it and
  // runs the updates due by then; `report` is overwritten.
  virtual void update(std::shared_ptr<const Observation> observation, const std::vector<SensorNow>& sensors,
                      UpdateReport& report) = 0;
  // The voxels the layer holds, as the last update left them (empty when it has none).
  virtual const mapping::VoxelMap& voxels() const = 0;
  // Whether the layer keeps voxels at all (nav2's ObstacleLayer keeps cells only): the 3D scores need them.
  virtual bool has_voxels() const { return true; }
  // The bytes the layer's map holds: STVL's voxel tree; nav2's voxel columns (4 bytes each) and the layer's own cells
  // (1 byte each). Buffers, the master and the bench's views aside.
  virtual std::size_t map_bytes() const = 0;
  // Whether costmap() needs voxels to exist (STVL's is their projection: none while the map is empty; nav2's layers
  // always have their window).
  virtual bool costmap_needs_voxels() const { return true; }
  // The layer's costmap as it would publish it now: its projection, with its footprint freed at the robot's pose
  // of the last observation.
  virtual mapping::Costmap2D costmap() const = 0;
  // nav2's ClearEntireCostmap at time_s on the costmap holding this layer (Costmap2DROS::resetLayers): the master,
  // if any, back to its default everywhere and the layer's reset(): STVL's (SpatioTemporalVoxelLayer::reset: every
  // voxel gone), nav2's (ObstacleLayer/VoxelLayer::reset: every cell and voxel back to the default). Both keep the
  // buffers' readings and restart their last-updated time at time_s (ResetLastUpdatedTime / resetLastUpdated); the
  // costmap is not current until its next update, which is (was_reset_: navigation::NavCostmap).
  virtual void reset(double time_s) = 0;
  // STVL's and nav2's isCurrent at a costmap update at time_s: every source with an expected_update_rate had a
  // reading (or a reset) within it (STVL: MeasurementBuffer::UpdatedAtExpectedRate in updateBounds; nav2:
  // ObservationBuffer::isCurrent in get*Observations). nav2's controller and planner wait for a current costmap
  // (costmap_update_timeout) and fail without one.
  virtual bool current(double /*time_s*/) const { return true; }
  // Every source's status (sensors in order, their sources in order), spans of staleness closed at until_s.
  virtual std::vector<SourceStatus> source_status(double until_s) const = 0;
  // nav2's master costmap this layer feeds (map.nav2_costmap), as the last update left it; null when not modelled.
  const Nav2Costmap* master() const { return master_.get(); }

 protected:
  std::unique_ptr<Nav2Costmap> master_;
};

// The layer config.type names (StvlLayer or Nav2Layer). Throws std::invalid_argument for a bad config.
std::unique_ptr<Layer> make_layer(LayerConfig config);

}  // namespace stvl::layer

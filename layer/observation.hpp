#pragma once
// What a costmap layer is fed: the observation sources of its sensors, one sensor frame's observation (clouds in
// the world frame, the optical frame's pose, the stamp) and where every sensor stands when it arrives. Plain
// structs: the pipeline makes observations (simulated or recorded), a layer buffers and applies them.
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "mapping/config.hpp"

namespace stvl::layer {

// nav2's ranges of one observation source (ObstacleLayer::onInitialize's defaults), metres.
struct Nav2SourceRanges {
  double obstacle_max_range_m = 2.5, obstacle_min_range_m = 0.0;
  double raytrace_max_range_m = 3.0, raytrace_min_range_m = 0.0;
  bool inf_is_valid = false;  // inf_is_valid: LaserScan's only; a PointCloud2 source never has an Inf point
};

// One STVL observation source (a sensor topic in STVL) fed by a camera's frames. A marking source marks the
// frame's decimated cloud with its own range and height band; a clearing source clears with its own frustum
// (or rays). A marking source and a clearing source on one camera, each with its own ranges, is STVL's
// common setup; one source that does both is this bench's default.
struct SourceConfig {
  std::string name = "camera";  // the source's name in STVL's observation_sources
  mapping::ObservationSource params;
  // nav2's layers: the source's ranges (obstacle_max_range, obstacle_min_range, raytrace_max_range,
  // raytrace_min_range, nav2's defaults); marking, clearing, the height band, observation_persistence and
  // expected_update_rate are params' (STVL's keys of the same names).
  Nav2SourceRanges nav2;
};

// One sensor feeding the layer: its name, the rate its frames are due at (Hz) and the sources its frames feed.
struct SensorConfig {
  std::string name = "camera";
  double rate_hz = 30.0;
  std::vector<SourceConfig> sources;
};

// One sensor frame as the layer takes it and its sources keep it (STVL's buffered observation).
struct Observation {
  std::size_t sensor_index = 0;  // into the layer's sensors
  double time_s = 0;  // when the layer takes it (simulated or recorded time): its clock, STVL's _last_updated
  // The header stamp, where camera timing makes it differ from time_s (NaN: time_s); STVL ages a buffered reading
  // by it (observation_persistence: _last_updated - header.stamp).
  double stamp_s = std::numeric_limits<double>::quiet_NaN();
  double header_stamp_s() const { return std::isnan(stamp_s) ? time_s : stamp_s; }
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();  // optical frame
  Eigen::Isometry3d T_world_base = Eigen::Isometry3d::Identity();    // the robot at time_s
  Eigen::Matrix3Xf decimated_W;                                      // after the voxel grid or CSNB: clears
  Eigen::Matrix3Xf marking_W;                                        // decimated and inside the passthrough band: marks
  // With a band in base_link (STVL's relative filters): marking_W's points in base_link, column for column (the
  // points the relative filters band, before they go to the global frame); empty otherwise.
  Eigen::Matrix3Xf marking_B;
  // With a clear_on_no_return source: one point per map voxel reached, at the source's max_z, by the rays of the
  // image's pixels without a return (empty otherwise).
  Eigen::Matrix3Xf no_return_W;
};

// Where one sensor stands when an observation arrives: its optical frame now and the time its next frame is due
// (infinity: none). A sensor that has missed a frame (an outage) has its buffers applied again.
struct SensorNow {
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  double next_frame_time_s = std::numeric_limits<double>::infinity();
};

// What STVL's buffer of `source` hands Mark from the observation: nothing for a source that does not mark, the
// marking cloud without a band (filter none), or the points inside the source's band (inclusive), its z in the
// world or, with z_reference base_link, in base_link (observation.marking_B, which must then match marking_W).
Eigen::Matrix3Xf source_marking_W(const Observation& observation, const mapping::ObservationSource& source);

// The marking height band of the sensors' marking sources (lowest min, highest max), as the costmap and the
// evaluation's truth use it; the first source's band when none marks (metres).
struct HeightBand {
  double min_m = 0.0, max_m = 3.0;
};
HeightBand marking_band(const std::vector<SensorConfig>& sensors);

}  // namespace stvl::layer

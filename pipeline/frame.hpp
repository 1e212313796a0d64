#pragma once
// What a run of the pipeline is made of and what one frame gives: the cameras and their STVL observation
// sources, the pipeline's config, one frame's result and stage times, a source's record over the run. Plain
// structs: the pipeline (pipeline.hpp), the stages after the depth image (map_stages.hpp), the evaluation, the
// replay and the outputs all speak them.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "filter/filter.hpp"
#include "common/voxel_key.hpp"
#include "mapping/config.hpp"
#include "mapping/nav2_costmap.hpp"
#include "pipeline/source_buffer.hpp"
#include "sensors/camera.hpp"
#include "sensors/depth_edge_filter.hpp"
#include "sensors/depth_image.hpp"
#include "sensors/depth_noise.hpp"
#include "sensors/gl_context.hpp"
#include "sim/simulator.hpp"
#include "sim/urdf_robot.hpp"

namespace stvl::pipeline {

// One STVL observation source (a sensor topic in STVL) fed by a camera's frames. A marking source marks the
// frame's decimated cloud with its own range and height band; a clearing source clears with its own frustum
// (or rays). A marking source and a clearing source on one camera, each with its own ranges, is STVL's
// common setup; one source that does both is this bench's default.
struct SourceConfig {
  std::string name = "camera";  // the source's name in STVL's observation_sources
  mapping::ObservationSource params;
};

// A time window in which a camera publishes no frame (a driver crash, a USB reset): [from_s, to_s).
struct Outage {
  double from_s = 0, to_s = 0;
};

// One depth camera on the robot, and the STVL observation sources it feeds.
struct CameraConfig {
  std::string name = "camera";  // its frames are <name>_link, <name>_depth_optical_frame; its topics /<name>/...
  sim::CameraMount mount;       // camera_link on base_link
  std::string frame;            // the URDF link the mount came from (robot.cameras[i].frame); empty: given as a mount
  sensors::CameraIntrinsics intrinsics = sensors::CameraIntrinsics::d435_848x480();  // also its rate and range
  sensors::GlBackend gl_backend = sensors::GlBackend::kAuto;
  sensors::DepthNoiseConfig noise;
  sensors::DepthEdgeFilterConfig edge_filter;  // ours, off by default: drops flying pixels before depth to cloud
  std::vector<SourceConfig> sources{SourceConfig{}};  // at least one
  std::vector<Outage> outages;  // sorted, disjoint, from_s >= 0: its frames in these windows are never taken
};

// Whether time_s lies in one of the camera's outages.
bool in_outage(const CameraConfig& camera, double time_s);

struct PipelineConfig {
  std::string world_path;  // MJCF file holding the robot (its <include file="robot.xml"/>)
  // robot.urdf: the robot built from a URDF, standing in for the world's robot.xml; null: robot.xml. sim.robot and
  // sim.drive follow it (config/).
  std::shared_ptr<const sim::UrdfRobot> urdf_robot;
  // A world built in memory instead (a scenario's nav2_map): its MJCF text, world_path then naming where it came
  // from; its <include>s (robot.xml) resolve against world_include_dir.
  std::string world_xml, world_include_dir;
  // Depth noise (per camera and frame; camera 0 uses it as it is, camera c > 0 a seed derived from it and c);
  // the filter's and odometry's seeds are their own.
  std::uint64_t seed = 1;
  sim::SimulatorConfig sim;  // the robot's controller and odometry (its camera_mount moves the model's camera site only)
  sim::Pose2D start_pose;
  sim::Path path;
  std::vector<sim::MocapTrack> moving_bodies;
  std::vector<CameraConfig> cameras{CameraConfig{}};  // names unique; mounts outside the robot and above the floor
  filter::FilterConfig filter;
  mapping::StvlConfig map;
  // nav2's master costmap with STVL as its layer (ours to model, mapping/nav2_costmap.hpp): YAML map.nav2_costmap;
  // off unless its width and height are given.
  mapping::Nav2CostmapConfig nav2_costmap;
  // Robot geoms the cameras see (sim::World::show_robot_geoms_to_cameras): drawn by the depth renderer, so
  // the map marks the robot's own body as STVL would; ground truth still skips them. Default: none.
  std::vector<std::string> robot_geoms_seen;
};

// Wall-clock milliseconds of one frame's stages (the only part of a run that is not deterministic). cloud_ms
// holds the camera's edge filter when it is enabled, then depth to cloud and the transform to the world. With
// several cameras at one instant the others draw ahead on their own threads (pipeline.hpp): their render_ms is
// the wait for that draw, and the drawing threads' time shows up in the stages the main thread ran meanwhile.
struct StageTimes {
  double render_ms = 0, noise_ms = 0, cloud_ms = 0, filter_ms = 0, clear_ms = 0, mark_ms = 0;
  double map_cpu_ms = 0;  // CPU time of the process (all threads) over clear + mark: blind to other processes
};

struct FrameResult {
  std::size_t camera_index = 0;
  std::string camera;
  std::size_t frame_index = 0;  // of this camera
  double time_s = 0;            // simulated
  // False when the robot fell over or left the world at time_s: nothing below the poses was computed, the map
  // was not updated, and the run should stop.
  bool robot_upright = true;
  Eigen::Isometry3d T_world_base = Eigen::Isometry3d::Identity();    // truth
  Eigen::Isometry3d T_odom_base = Eigen::Isometry3d::Identity();     // wheel odometry
  Eigen::Isometry3d T_map_odom = Eigen::Isometry3d::Identity();      // odometry drift (map = world)
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();  // optical frame
  double odom_v_mps = 0, odom_omega_radps = 0;
  sensors::DepthImage clean_depth;  // rendered, noise-free
  sensors::DepthImage depth;        // with the camera's noise model (what the camera publishes)
  // With the camera's edge filter enabled: `depth` without the pixels it dropped (the image the cloud comes
  // from; pixels it dropped are not "no return" pixels); empty otherwise.
  sensors::DepthImage edge_filtered_depth;
  std::size_t edge_dropped_pixels = 0;
  // Valid pixels in the optical frame, row-major pixel order: the first point_count columns of points_C.
  Eigen::Matrix3Xf points_C;
  Eigen::Index point_count = 0;
  auto cloud_C() const { return points_C.leftCols(point_count); }  // the valid points (a view of points_C)
  Eigen::Matrix3Xf cloud_W;      // the same points in the world frame
  Eigen::Matrix3Xf decimated_W;  // after the voxel grid or CSNB: clears
  Eigen::Matrix3Xf marking_W;    // decimated and inside the passthrough band: marks
  // With a band in base_link (band_frame()): marking_W's points in base_link, column for column (the points STVL's
  // relative filters band, before they go to the global frame); empty otherwise.
  Eigen::Matrix3Xf marking_B;
  // With a clear_on_no_return source: one point per map voxel reached, at the source's max_z, by the rays of
  // the noisy image's pixels without a return (empty otherwise).
  Eigen::Matrix3Xf no_return_W;
  // Voxels this frame's clearing removed: the rays (ray-cast mode) or the frustum's acceleration (frustum mode);
  // not those that expired by plain decay.
  // With map.footprint_clearing_height_m (ours), the voxels removed inside the footprint are among them too.
  std::vector<VoxelKey> cleared_keys;
  std::size_t footprint_cleared = 0;  // voxels removed inside the robot's footprint this update (ours)
  // Readings of earlier frames this update applied again from the sources' buffers (observation_persistence, or
  // a stopped camera's buffer, as STVL applies every buffer at every update).
  std::size_t reapplied_readings = 0;
  // Every reading an update took, in the order STVL's layer takes them (cameras in order, each camera's sources
  // in order, each buffer newest first), this instant's and earlier frames' alike; the bag writes them at the
  // update (run/bag_recorder.hpp).
  struct AppliedReading {
    std::size_t camera_index = 0, source_index = 0;
    std::shared_ptr<const SourceReading> reading;
  };
  // The map updates this frame ran, in time order: with map.update_frequency the ticks since the last frame
  // (earlier than time_s), then the one at time_s when it is a tick; otherwise at most one, at time_s.
  struct MapUpdate {
    double time_s = 0;
    std::vector<AppliedReading> applied_readings;
  };
  std::vector<MapUpdate> updates;
  // True when updates is not empty. False when this frame's reading only went into its sources' buffers:
  // another camera takes a frame at the same time, and STVL's update of that instant (map.update_grouping:
  // instant) runs at the last of them, or the costmap's next tick (map.update_frequency) is later.
  bool map_updated = true;
  StageTimes times;
};

// nav2's master costmap against STVL's layer over a run (PipelineConfig::nav2_costmap): after each update, the
// master cells lethal where the layer is not (ghosts, STVL #199).
struct Nav2Ghosts {
  std::size_t updates = 0, updates_with_ghosts = 0, max_cells = 0, last_cells = 0;
  double max_at_s = 0.0;  // the first update with max_cells
};

// One observation source's record over the run: when it was not current (STVL's expected_update_rate) and
// what its buffer applied again.
struct SourceStatus {
  std::string source;
  std::size_t camera_index = 0;
  double expected_update_rate_s = 0;
  std::vector<StaleSpan> stale;     // in time order; the last one may end at the time asked for (still stale)
  std::size_t reapplied_readings = 0;  // readings applied at a later update than their own frame's
  double max_reapplied_age_s = 0;      // the oldest of those at the update that applied it
  double reapplied_max_distance_m = 0;  // farthest a re-applied reading's optical centre lay from the camera's pose then
};

// The marking height band of the config's marking sources (lowest min, highest max), as the costmap and the
// evaluation's truth use it; the first source's band when none marks.
struct HeightBand {
  double min_m = 0.0, max_m = 3.0;
};
// The config's band as HeightBand says (metres).
HeightBand marking_band(const PipelineConfig& config);
// The frame the banded marking sources measure their band's z in (their z_reference, which validate_cameras()
// requires them to share; global when none is banded): the frame the pipeline filters each cloud in.
mapping::ZReference band_frame(const PipelineConfig& config);

// Throws std::invalid_argument naming the camera (and source) for: no camera, an empty or repeated camera
// name, a camera without sources, a source name used twice, bad intrinsics, noise, edge filter or source
// parameters, banded marking sources with different z_reference frames, a mount that is not finite, below the
// floor, or farther than 2 m from base_link. (A mount inside
// the robot's body needs the world: the Pipeline checks that.)
void validate_cameras(const PipelineConfig& config);

// The decimation the pipeline runs on the whole cloud: the filter without its passthrough (which applies to
// the marking cloud only).
filter::FilterConfig decimation_config(filter::FilterConfig config);

}  // namespace stvl::pipeline

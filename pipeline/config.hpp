#pragma once
// What a run of the pipeline is made of: the cameras and the observation sources they feed, the world, the robot,
// the filter, and the layer's settings, in one plain config (config/ reads it from a scenario).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "filter/filter.hpp"
#include "layer/stvl_layer.hpp"
#include "layer/tf_filter.hpp"
#include "mapping/config.hpp"
#include "sensors/camera.hpp"
#include "sensors/camera_timing.hpp"
#include "sensors/depth_edge_filter.hpp"
#include "sensors/depth_noise.hpp"
#include "sensors/gl_context.hpp"
#include "sim/simulator.hpp"

namespace stvl::sim {
struct UrdfRobot;
}  // namespace stvl::sim

namespace stvl::pipeline {

using layer::SourceConfig;

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
  // The bench's, off by default (STVL has none): drops flying pixels before depth to cloud.
  sensors::DepthEdgeFilterConfig edge_filter;
  std::vector<SourceConfig> sources{SourceConfig{}};  // at least one
  std::vector<Outage> outages;  // sorted, disjoint, from_s >= 0: its frames in these windows are never taken
  // When its frames reach the map and what their stamps say (YAML camera.timing; off: a perfect camera).
  sensors::CameraTimingConfig timing;
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
  sim::SimulatorConfig
      sim;  // the robot's controller and odometry (its camera_mount moves the model's camera site only)
  sim::Pose2D start_pose;
  sim::Path path;
  std::vector<sim::MocapTrack> moving_bodies;
  std::vector<CameraConfig> cameras{CameraConfig{}};  // names unique; mounts outside the robot and above the floor
  filter::FilterConfig filter;
  mapping::StvlConfig map;
  layer::LayerType layer_type = layer::LayerType::kStvl;  // YAML map.layer_type
  layer::Nav2LayerParams nav2_layer;                      // YAML map.nav2_layer (nav2 layer types)
  // nav2's master costmap around the layer (layer/nav2_costmap.hpp): YAML map.nav2_costmap; off unless its width
  // and height are given.
  layer::Nav2CostmapConfig nav2_costmap;
  // tf as the robot has it (YAML tf) and the layer's transform_tolerance, for cameras with timing.
  layer::TfTimingConfig tf;
  bool timing_enabled() const;  // a camera has timing, tf.odom_latency_s > 0, or localization is enabled
  // Robot geoms the cameras see (sim::World::show_robot_geoms_to_cameras): drawn by the depth renderer, so
  // the map marks the robot's own body as STVL would; ground truth still skips them. Default: none.
  std::vector<std::string> robot_geoms_seen;
};

// The layer's config: its type, the map, nav2's layer keys and master costmap, and each camera as a sensor (its name,
// rate and sources).
layer::LayerConfig layer_config(const PipelineConfig& config);

// The config's marking band (layer::marking_band over its cameras' sources).
layer::HeightBand marking_band(const PipelineConfig& config);
// The frame the banded marking sources measure their band's z in (their z_reference, which validate_cameras()
// requires them to share; global when none is banded): the frame the pipeline filters each cloud in.
mapping::ZReference band_frame(const PipelineConfig& config);

// Throws std::invalid_argument naming the camera (and source) for: no camera, an empty or repeated camera
// name, a camera without sources, a source name used twice, bad intrinsics, noise, edge filter or source
// parameters, banded marking sources with different z_reference frames, a mount that is not finite, below the
// floor, or farther than 2 m from base_link. (A mount inside the robot's body needs the world: the Pipeline
// checks that.)
void validate_cameras(const PipelineConfig& config);

// The decimation the pipeline runs on the whole cloud: the filter without its passthrough (which applies to
// the marking cloud only).
filter::FilterConfig decimation_config(filter::FilterConfig config);

}  // namespace stvl::pipeline

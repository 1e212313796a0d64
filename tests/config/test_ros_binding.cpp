// Binding an STVL layer from a ROS parameter file to the scenario's cameras (tools/ros_binding.hpp), and
// map.ros_params in a scenario.
#include "config/ros_binding.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/config/ros_texts.hpp"
#include "tests/config/scenario_texts.hpp"

namespace stvl::config {
namespace {

using ::testing::HasSubstr;
using namespace test;

pipeline::PipelineConfig cameras(std::initializer_list<const char*> names) {
  pipeline::PipelineConfig c;
  c.cameras.clear();
  for (const char* name : names) {
    pipeline::CameraConfig camera;
    camera.name = camera.sources.front().name = name;
    c.cameras.push_back(camera);
  }
  return c;
}

RosObservationSource source(const std::string& topic, const std::string& frame = "") {
  RosObservationSource s;
  s.topic = topic;
  s.sensor_frame = frame;
  return s;
}

TEST(RosBinding, TheTopicOrTheSensorFrameNamesTheCamera) {
  const auto c = cameras({"front", "front_low", "back"}).cameras;
  EXPECT_EQ(bound_camera_index(source("/front/depth/points"), c), 0);
  EXPECT_EQ(bound_camera_index(source("front/depth/points"), c), 0);
  EXPECT_EQ(bound_camera_index(source("/front_low/depth/points"), c), 1);
  EXPECT_EQ(bound_camera_index(source("/cloud", "back_depth_optical_frame"), c), 2);
  EXPECT_EQ(bound_camera_index(source("", "front_low_link"), c), 1);          // the longest name, not front
  EXPECT_EQ(bound_camera_index(source("/back/points", "front_link"), c), 2);  // the topic first
  EXPECT_EQ(bound_camera_index(source("/frontal/points", "fronts"), c), -1);
  EXPECT_EQ(bound_camera_index(source("/camera/depth/points"), c), -1);
}

// ROS 1's common setup: a marking and a clearing source on one camera, each with its own ranges, and a
// disabled source.
const char* const kMarkAndClear = R"(voxel_size: 0.05
voxel_decay: 10.0
decay_model: 1
mark_threshold: 2
observation_sources: front_mark front_clear spare
front_mark:
  topic: /front/depth/points
  marking: true
  clearing: false
  obstacle_range: 2.0
  min_obstacle_height: 0.1
  max_obstacle_height: 1.5
  filter: voxel
  voxel_min_points: 4
front_clear:
  sensor_frame: front_depth_optical_frame
  marking: false
  clearing: true
  max_z: 6.0
  decay_acceleration: 5.0
  filter: voxel
spare:
  topic: /nowhere/points
  enabled: false
)";

TEST(RosBinding, MarkingAndClearingSourcesOfOneCameraKeepTheirOwnValues) {
  const stvl::test::TempDir dir("ros_binding");
  const RosStvlLayer layer = load_ros_stvl_layer(write_file(dir, "p.yaml", ros1_text(kMarkAndClear)), "stvl_layer");
  pipeline::PipelineConfig c = cameras({"front"});
  apply_ros_layer(layer, c, true);
  EXPECT_DOUBLE_EQ(c.map.voxel_decay_s, 10.0);
  EXPECT_EQ(c.map.decay_model, mapping::DecayModel::kExponential);
  EXPECT_EQ(c.map.mark_threshold, 2);
  const auto& sources = c.cameras[0].sources;
  ASSERT_EQ(sources.size(), 2u);  // the disabled one is left out
  EXPECT_EQ(sources[0].name, "front_mark");
  EXPECT_TRUE(sources[0].params.marking);
  EXPECT_FALSE(sources[0].params.clearing);
  EXPECT_DOUBLE_EQ(sources[0].params.obstacle_range_m, 2.0);
  EXPECT_EQ(sources[1].name, "front_clear");
  EXPECT_FALSE(sources[1].params.marking);
  EXPECT_TRUE(sources[1].params.clearing);
  EXPECT_DOUBLE_EQ(sources[1].params.max_z_m, 6.0);
  EXPECT_DOUBLE_EQ(sources[1].params.decay_acceleration_per_s3, 5.0);
  // filter: voxel -> a voxel grid at the layer's voxel size, then the marking sources' band.
  EXPECT_EQ(c.filter.type, filter::FilterType::kVoxel);
  EXPECT_DOUBLE_EQ(c.filter.voxel.voxel_size_m, 0.05);
  EXPECT_TRUE(c.filter.passthrough_enabled);
  EXPECT_DOUBLE_EQ(c.filter.passthrough.min_z_m, 0.1);
  EXPECT_DOUBLE_EQ(c.filter.passthrough.max_z_m, 1.5);
  // STVL's VoxelGrid takes the band as z limits before counting; Noetic's PCL 1.10 ignores voxel_min_points.
  EXPECT_TRUE(c.filter.band_before_decimation);
  EXPECT_EQ(c.filter.voxel.min_points_per_voxel, 1);
  EXPECT_TRUE(sources[0].params.height_band);
  // The same layer read by ROS 2's rules (Humble and later, PCL >= 1.12) drops leaves of fewer than 4 points.
  pipeline::PipelineConfig ros2 = cameras({"front"});
  apply_ros_layer(load_ros_stvl_layer(write_file(dir, "bare.yaml", kMarkAndClear), ""), ros2, true);
  EXPECT_EQ(ros2.filter.voxel.min_points_per_voxel, 4);
  EXPECT_TRUE(ros2.filter.band_before_decimation);
  // A scenario's own filter is kept.
  pipeline::PipelineConfig own = cameras({"front"});
  own.filter.type = filter::FilterType::kCsnb;
  apply_ros_layer(layer, own, false);
  EXPECT_EQ(own.filter.type, filter::FilterType::kCsnb);
  // filter none: STVL's buffer filters nothing, so no band on the cloud and none at marking.
  std::string none = kMarkAndClear;
  for (std::size_t at = none.find("filter: voxel"); at != std::string::npos; at = none.find("filter: voxel"))
    none.replace(at, 13, "filter: none");
  pipeline::PipelineConfig unbanded = cameras({"front"});
  apply_ros_layer(load_ros_stvl_layer(write_file(dir, "none.yaml", none), ""), unbanded, true);
  EXPECT_FALSE(unbanded.filter.passthrough_enabled);
  EXPECT_EQ(unbanded.filter.type, filter::FilterType::kNone);
  EXPECT_FALSE(unbanded.cameras[0].sources[0].params.height_band);
}

// The ros2 branch's relative filters (PR #304 as 22f7927): the band (and for voxel_relative the leaves) in
// z_reference_frame, which defaults to the global frame; ROS 1 (noetic) knows neither and applies no filter.
TEST(RosBinding, RelativeFiltersBandInZReferenceFrame) {
  const stvl::test::TempDir dir("ros_binding_relative");
  const auto bind = [&](const std::string& filter, const std::string& extra, bool ros1 = false) {
    std::string text = kMarkAndClear;
    for (std::size_t at = text.find("filter: voxel"); at != std::string::npos; at = text.find("filter: voxel", at + 1))
      text.replace(at, 13, "filter: " + filter + extra);
    pipeline::PipelineConfig c = cameras({"front"});
    apply_ros_layer(load_ros_stvl_layer(write_file(dir, "r.yaml", ros1 ? ros1_text(text) : text), ""), c, true);
    return c;
  };
  const std::string base = "\n  z_reference_frame: base_link";
  pipeline::PipelineConfig c = bind("passthrough_relative", base);
  EXPECT_EQ(c.cameras[0].sources[0].params.z_reference, mapping::ZReference::kBaseLink);
  EXPECT_TRUE(c.cameras[0].sources[0].params.height_band);
  EXPECT_EQ(c.filter.type, filter::FilterType::kNone);
  EXPECT_FALSE(c.filter.band_before_decimation);
  EXPECT_EQ(pipeline::band_frame(c), mapping::ZReference::kBaseLink);
  c = bind("voxel_relative", base);
  EXPECT_EQ(c.filter.type, filter::FilterType::kVoxel);
  EXPECT_TRUE(c.filter.band_before_decimation);
  EXPECT_EQ(pipeline::band_frame(c), mapping::ZReference::kBaseLink);
  // STVL's default z_reference_frame is the global frame: the same as passthrough.
  c = bind("passthrough_relative", "");
  EXPECT_EQ(c.cameras[0].sources[0].params.z_reference, mapping::ZReference::kGlobal);
  c = bind("passthrough_relative", "\n  z_reference_frame: odom");
  EXPECT_EQ(c.cameras[0].sources[0].params.z_reference, mapping::ZReference::kGlobal);
  // z_reference_frame is read by the relative filters only.
  c = bind("passthrough", base);
  EXPECT_EQ(c.cameras[0].sources[0].params.z_reference, mapping::ZReference::kGlobal);
  // A frame the bench does not simulate is an error naming the source and the frames it has.
  EXPECT_THAT(invalid_argument_of([&] { bind("voxel_relative", "\n  z_reference_frame: imu_link"); }),
              HasSubstr("z_reference_frame 'imu_link': the bench's frames for a height band are the global frame"));
}

std::string binding_error(const std::string& body, pipeline::PipelineConfig c) {
  const stvl::test::TempDir dir("ros_binding_errors");
  const std::string path = write_file(dir, "p.yaml", ros1_text(body));
  return file_as_FILE(invalid_argument_of([&] { apply_ros_layer(load_ros_stvl_layer(path, ""), c, true); }), path);
}

TEST(RosBinding, BadBindingsNameFileLineAndSource) {
  // ros1_text puts the layer body from line 6: front_mark's mapping is on line 11.
  EXPECT_THAT(binding_error(kMarkAndClear, cameras({"rear"})),
              HasSubstr("FILE:11: stvl_layer.front_mark: bound to no camera: topic '/front/depth/points' and "
                        "sensor_frame '' name none of the cameras (rear)"));
  EXPECT_THAT(binding_error(kMarkAndClear, cameras({"front", "rear"})),
              HasSubstr("FILE: stvl_layer: no enabled observation source is bound to camera 'rear'"));
  std::string mixed = kMarkAndClear;
  mixed.replace(mixed.rfind("filter: voxel"), 13, "filter: none");
  EXPECT_THAT(binding_error(mixed, cameras({"front"})),
              HasSubstr("FILE:20: stvl_layer.front_clear: filter none differs from front_mark's voxel"));
}

// nav2: a non-empty footprint wins over robot_radius; neither: no footprint (nothing cleared).
TEST(RosBinding, TheCostmapsFootprintFeedsFootprintClearing) {
  RosStvlLayer layer;
  layer.sources.push_back(source("/front/depth/points"));
  layer.update_footprint_enabled = false;
  pipeline::PipelineConfig config = cameras({"front"});
  const auto bind = [&] {
    config.map.footprint_B = {{9, 9}, {9, 8}, {8, 8}};
    apply_ros_layer(layer, config, false);
  };
  bind();
  EXPECT_FALSE(config.map.update_footprint_enabled);
  EXPECT_TRUE(config.map.footprint_B.empty());
  layer.robot_radius_m = 0.3;
  bind();
  ASSERT_EQ(config.map.footprint_B.size(), 16u);
  EXPECT_NEAR(config.map.footprint_B[4].y(), 0.3, 1e-12);
  layer.footprint = std::vector<Eigen::Vector2d>{{0.3, 0.2}, {0.3, -0.2}, {-0.2, -0.2}, {-0.2, 0.2}};
  bind();
  EXPECT_EQ(config.map.footprint_B.size(), 4u);
}

TEST(RosBinding, AScenarioTakesItsMapFromRosParams) {
  const Scenario s = load_scenario(std::string(STVL_SOURCE_DIR) + "/scenarios/nav2_stvl_tutorial.yaml");
  ASSERT_TRUE(s.ros_params);
  EXPECT_THAT(s.ros_params->path, HasSubstr("scenarios/ros/nav2_stvl_tutorial.yaml"));
  ASSERT_EQ(s.camera().sources.size(), 1u);
  const auto& p = s.camera().sources[0].params;
  EXPECT_EQ(s.camera().sources[0].name, "pointcloud");
  EXPECT_DOUBLE_EQ(p.obstacle_range_m, 2.5);  // the layer-level 3.0 is not read by ROS 2
  EXPECT_DOUBLE_EQ(p.horizontal_fov_rad, 1.048);
  EXPECT_DOUBLE_EQ(p.decay_acceleration_per_s3, 15.0);
  EXPECT_EQ(s.pipeline.filter.type, filter::FilterType::kNone);  // passthrough: ROS 2's default filter
  EXPECT_TRUE(s.pipeline.filter.passthrough_enabled);
  EXPECT_DOUBLE_EQ(s.pipeline.map.voxel_decay_s, 15.0);
  // The local costmap's 3 x 3 m rolling window at 0.05 m: nav2's master costmap around the layer.
  EXPECT_DOUBLE_EQ(s.pipeline.nav2_costmap.width_m, 3.0);
  EXPECT_DOUBLE_EQ(s.pipeline.nav2_costmap.height_m, 3.0);
  EXPECT_DOUBLE_EQ(s.pipeline.nav2_costmap.resolution_m, 0.05);
  EXPECT_TRUE(s.pipeline.nav2_costmap.rolling_window);
  EXPECT_FALSE(s.pipeline.nav2_costmap.track_unknown_space);  // the costmap's; the layer's own is true
  // The tutorial's robot_radius 0.22 and update_footprint_enabled true: STVL's footprint clearing.
  EXPECT_TRUE(s.pipeline.map.update_footprint_enabled);
  ASSERT_EQ(s.pipeline.map.footprint_B.size(), 16u);
  EXPECT_NEAR(s.pipeline.map.footprint_B[0].x(), 0.22, 1e-12);
  for (const char* key :
       {"update_footprint_enabled: false", "robot_radius: 0.3", "footprint: [[1, 0], [0, 1], [0, 0]]"})
    EXPECT_THAT(error_of(std::string(kMinimal) + "map:\n  ros_params: p.yaml\n  " + key + "\n"),
                HasSubstr("comes from the ROS parameter file"))
        << key;
  const std::string with_size = std::string(kMinimal) + "map:\n  ros_params: p.yaml\n  voxel_size: 0.1\n";
  EXPECT_THAT(error_of(with_size), HasSubstr(at(8, "map.voxel_size") + "comes from the ROS parameter file"));
  EXPECT_THAT(error_of(std::string(kMinimal) + "map:\n  ros_params: /nonexistent/p.yaml\n"),
              HasSubstr("/nonexistent/p.yaml: no such file"));
}

}  // namespace
}  // namespace stvl::config

#include "config/ros_params.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/config/ros_texts.hpp"
#include "tests/support/invalid_argument.hpp"

namespace stvl::config {
namespace {

using test::invalid_argument_of;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

class RosParams : public ::testing::Test {
 protected:
  std::string file(const std::string& text) {
    return test::write_file(dir_, "p" + std::to_string(n_++) + ".yaml", text);
  }
  RosStvlLayer load(const std::string& text, const std::string& layer = "", const std::string& costmap = "") {
    return load_ros_stvl_layer(file(text), layer, costmap);
  }
  std::string error(const std::string& text, const std::string& layer = "", const std::string& costmap = "") {
    const std::string path = file(text);
    return test::file_as_FILE(invalid_argument_of([&] { load_ros_stvl_layer(path, layer, costmap); }), path);
  }
  stvl::test::TempDir dir_{"ros_params"};
  int n_ = 0;
};

TEST_F(RosParams, ReadsTheNav2TutorialFileByRos2Rules) {
  const RosStvlLayer l = load_ros_stvl_layer(test::kTutorialFile, "stvl_layer");
  EXPECT_EQ(l.flavour, RosFlavour::kRos2);
  EXPECT_EQ(l.layer_name, "stvl_layer");
  EXPECT_EQ(l.costmap_name, "local_costmap");
  EXPECT_DOUBLE_EQ(l.map.voxel_decay_s, 15.0);
  EXPECT_EQ(l.map.decay_model, mapping::DecayModel::kLinear);
  EXPECT_DOUBLE_EQ(l.map.voxel_size_m, 0.05);
  EXPECT_TRUE(l.track_unknown_space);
  EXPECT_TRUE(l.publish_voxel_map);
  EXPECT_DOUBLE_EQ(l.map_save_duration_s, 60.0);
  EXPECT_EQ(l.resolution_m, 0.05);
  EXPECT_EQ(l.robot_radius_m, 0.22);
  EXPECT_EQ(l.width_m, 3.0);
  EXPECT_EQ(l.rolling_window, true);
  EXPECT_FALSE(l.footprint);
  ASSERT_EQ(l.sources.size(), 1u);
  const RosObservationSource& s = l.sources[0];
  EXPECT_EQ(s.name, "pointcloud");
  EXPECT_EQ(s.line, 42);
  EXPECT_EQ(s.topic, "/intel_realsense_r200_depth/points");
  EXPECT_DOUBLE_EQ(s.stvl.obstacle_range_m, 2.5);  // the layer-level obstacle_range: 3.0 is not read by ROS 2
  EXPECT_DOUBLE_EQ(s.stvl.max_obstacle_height_m, 2.0);
  EXPECT_DOUBLE_EQ(s.stvl.min_z_m, 0.1);
  EXPECT_DOUBLE_EQ(s.stvl.max_z_m, 7.0);
  EXPECT_DOUBLE_EQ(s.stvl.vertical_fov_rad, 0.8745);
  EXPECT_DOUBLE_EQ(s.stvl.horizontal_fov_rad, 1.048);
  EXPECT_DOUBLE_EQ(s.stvl.decay_acceleration_per_s3, 15.0);
  EXPECT_EQ(s.filter, RosSourceFilter::kPassthrough);  // voxel_filter: false is ignored; filter's default
  EXPECT_TRUE(s.clear_after_reading);
  EXPECT_TRUE(s.stvl.clearing);
}

TEST_F(RosParams, TheThreeFormsReadToTheSameValues) {
  const RosStvlLayer ros2 = load(test::nav2_text(test::kLayerBody));
  const RosStvlLayer ros1 = load(test::ros1_text(test::kLayerBody));
  const RosStvlLayer bare = load(test::kLayerBody);
  EXPECT_EQ(ros2.flavour, RosFlavour::kRos2);
  EXPECT_EQ(ros1.flavour, RosFlavour::kRos1);
  EXPECT_EQ(bare.flavour, RosFlavour::kBare);
  EXPECT_EQ(ros1.costmap_name, "local_costmap");
  EXPECT_EQ(ros1.resolution_m, 0.05);
  for (const RosStvlLayer* l : {&ros1, &bare}) {
    EXPECT_EQ(l->map.voxel_decay_s, ros2.map.voxel_decay_s);
    EXPECT_EQ(l->map.voxel_size_m, ros2.map.voxel_size_m);
    EXPECT_EQ(l->map.decay_model, ros2.map.decay_model);
    EXPECT_EQ(l->track_unknown_space, ros2.track_unknown_space);
    EXPECT_EQ(l->publish_voxel_map, ros2.publish_voxel_map);
    EXPECT_EQ(l->map_save_duration_s, ros2.map_save_duration_s);
    ASSERT_EQ(l->sources.size(), 1u);
    const auto& a = l->sources[0];
    const auto& b = ros2.sources[0];
    EXPECT_EQ(a.topic, b.topic);
    EXPECT_EQ(a.stvl.obstacle_range_m, 3.0);
    EXPECT_EQ(a.stvl.obstacle_range_m, b.stvl.obstacle_range_m);
    EXPECT_EQ(a.stvl.max_obstacle_height_m, b.stvl.max_obstacle_height_m);
    EXPECT_EQ(a.stvl.min_z_m, b.stvl.min_z_m);
    EXPECT_EQ(a.stvl.max_z_m, b.stvl.max_z_m);
    EXPECT_EQ(a.stvl.horizontal_fov_rad, b.stvl.horizontal_fov_rad);
    EXPECT_EQ(a.stvl.vertical_fov_rad, b.stvl.vertical_fov_rad);
    EXPECT_EQ(a.stvl.decay_acceleration_per_s3, b.stvl.decay_acceleration_per_s3);
    EXPECT_EQ(a.filter, b.filter);
    EXPECT_EQ(a.clear_after_reading, b.clear_after_reading);
  }
}

TEST_F(RosParams, Ros2DefaultsWhenAbsent) {
  const RosStvlLayer l = load(test::nav2_text("voxel_decay: 15.0\nobservation_sources: cam\ncam: {}\n"));
  EXPECT_DOUBLE_EQ(l.map.voxel_size_m, 0.05);
  EXPECT_EQ(l.decay_model_code, 0);
  EXPECT_EQ(l.map.mark_threshold, 0);
  EXPECT_EQ(l.combination_method, 1);
  EXPECT_TRUE(l.update_footprint_enabled);
  EXPECT_FALSE(l.track_unknown_space);
  EXPECT_FALSE(l.mapping_mode);
  EXPECT_FALSE(l.publish_voxel_map);
  EXPECT_TRUE(l.enabled);
  EXPECT_DOUBLE_EQ(l.map_save_duration_s, 60.0);
  EXPECT_DOUBLE_EQ(l.transform_tolerance_s, 0.2);
  const RosObservationSource& s = l.sources.at(0);
  EXPECT_EQ(s.data_type, "PointCloud2");
  EXPECT_EQ(s.topic, "");
  EXPECT_TRUE(s.stvl.marking);
  EXPECT_FALSE(s.stvl.clearing);
  EXPECT_DOUBLE_EQ(s.stvl.obstacle_range_m, 2.5);
  EXPECT_DOUBLE_EQ(s.stvl.min_obstacle_height_m, 0.0);
  EXPECT_DOUBLE_EQ(s.stvl.max_obstacle_height_m, 3.0);
  EXPECT_DOUBLE_EQ(s.stvl.min_z_m, 0.0);
  EXPECT_DOUBLE_EQ(s.stvl.max_z_m, 10.0);
  EXPECT_DOUBLE_EQ(s.stvl.vertical_fov_rad, 0.7);
  EXPECT_DOUBLE_EQ(s.stvl.horizontal_fov_rad, 1.04);
  EXPECT_DOUBLE_EQ(s.stvl.decay_acceleration_per_s3, 0.0);
  EXPECT_EQ(s.filter, RosSourceFilter::kPassthrough);
  EXPECT_EQ(s.voxel_min_points, 0);
  EXPECT_FALSE(s.clear_after_reading);
  EXPECT_FALSE(s.inf_is_valid);
  EXPECT_TRUE(s.enabled);
  EXPECT_EQ(s.model_type, 0);
}

TEST_F(RosParams, Ros1DefaultsAndSearchParamForObstacleRange) {
  const std::string body = "voxel_decay: 15.0\nobservation_sources: cam\ncam: {}\n";
  const RosStvlLayer l = load(test::ros1_text(body));
  EXPECT_EQ(l.sources.at(0).topic, "cam");  // ROS 1's default topic is the source's name
  EXPECT_DOUBLE_EQ(l.sources.at(0).stvl.obstacle_range_m, 3.0);
  // searchParam: the layer's obstacle_range, else the costmap namespace's (costmap_common_params style).
  const RosStvlLayer layer_level = load(test::ros1_text("obstacle_range: 2.0\n" + body));
  EXPECT_DOUBLE_EQ(layer_level.sources.at(0).stvl.obstacle_range_m, 2.0);
  const RosStvlLayer root_level = load(
      "obstacle_range: 1.5\ntrack_unknown_space: true\nplugins:\n"
      "  - {name: stvl, type: spatio_temporal_voxel_layer/SpatioTemporalVoxelLayer}\nstvl:\n" +
      test::indented(body, 2));
  EXPECT_EQ(root_level.costmap_name, "");
  EXPECT_DOUBLE_EQ(root_level.sources.at(0).stvl.obstacle_range_m, 1.5);
  EXPECT_TRUE(root_level.track_unknown_space);  // STVL's default follows the costmap's
}

TEST_F(RosParams, DecayModelsOtherThanZeroAndOneArePersistent) {
  for (const int code : {5, -1, 2}) {
    const RosStvlLayer l =
        load("voxel_decay: 15.0\ndecay_model: " + std::to_string(code) + "\nobservation_sources: cam\ncam: {}\n");
    EXPECT_EQ(l.decay_model_code, code);
    EXPECT_EQ(l.map.decay_model, mapping::DecayModel::kPersistent) << code;
  }
  EXPECT_EQ(load("voxel_decay: 1.0\ndecay_model: 1\nobservation_sources: c\nc: {}\n").map.decay_model,
            mapping::DecayModel::kExponential);
}

TEST_F(RosParams, FilterStringsAndRos1VoxelFilter) {
  const auto filter_of = [&](const std::string& text, bool ros1) {
    const std::string body = "voxel_decay: 15.0\nobservation_sources: c\nc:\n" + test::indented(text, 2);
    return load(ros1 ? test::ros1_text(body) : body).sources.at(0).filter;
  };
  EXPECT_EQ(filter_of("filter: voxel\n", false), RosSourceFilter::kVoxel);
  EXPECT_EQ(filter_of("filter: passthrough\n", false), RosSourceFilter::kPassthrough);
  EXPECT_EQ(filter_of("filter: none\n", false), RosSourceFilter::kNone);
  EXPECT_EQ(filter_of("filter: \"\"\n", false), RosSourceFilter::kNone);
  EXPECT_EQ(filter_of("voxel_filter: true\n", false), RosSourceFilter::kPassthrough);  // ROS 2 ignores it
  EXPECT_EQ(filter_of("voxel_filter: true\n", true), RosSourceFilter::kVoxel);         // melodic
  EXPECT_EQ(filter_of("voxel_filter: false\n", true), RosSourceFilter::kPassthrough);
  EXPECT_EQ(filter_of("voxel_filter: true\nfilter: none\n", true), RosSourceFilter::kNone);  // noetic
}

TEST_F(RosParams, FootprintAsStringOrList) {
  const std::string body =
      "  stvl:\n    plugin: spatio_temporal_voxel_layer/SpatioTemporalVoxelLayer\n    voxel_decay: 15.0\n    "
      "observation_sources: c\n    c: {}\n";
  const std::string head = "c:\n  c:\n    ros__parameters:\n      plugins: [stvl]\n";
  const auto with = [&](const std::string& footprint) {
    return head + "      footprint: " + footprint + "\n" + test::indented(body, 4);
  };
  const auto text_form = load(with("\"[[0.2, 0.1], [0.2, -0.1], [-0.2, -0.1]]\"")).footprint;
  ASSERT_TRUE(text_form);
  ASSERT_EQ(text_form->size(), 3u);
  EXPECT_DOUBLE_EQ((*text_form)[1].y(), -0.1);
  EXPECT_EQ(load(with("[[0.2, 0.1], [0.2, -0.1], [-0.2, -0.1]]")).footprint->size(), 3u);
  EXPECT_FALSE(load(with("\"[]\"")).footprint);
  EXPECT_THAT(error(with("\"[[0.2, 0.1]]\"")), HasSubstr(":5: c.footprint: needs at least three points"));
}

TEST_F(RosParams, MalformedYamlNamesFileAndLine) {
  const std::string message = error("stvl:\n  voxel_decay: [1, 2\n  observation_sources: c\n");
  EXPECT_THAT(message, StartsWith("FILE:"));
  EXPECT_THAT(message, HasSubstr("YAML syntax error"));
}

TEST_F(RosParams, MissingLayerListsTheLayersThere) {
  const std::string message = error(test::nav2_text(test::kLayerBody), "voxel_layer");
  EXPECT_THAT(message, StartsWith("FILE:5: local_costmap.plugins: no layer 'voxel_layer' (layers: stvl_layer in "
                                  "local_costmap (spatio_temporal_voxel_layer/SpatioTemporalVoxelLayer))"));
  EXPECT_THAT(error(test::kLayerBody, "", "global_costmap"), HasSubstr("global_costmap: no costmap of that name"));
}

TEST_F(RosParams, NonStvlPluginIsNamed) {
  const std::string message = error(test::nav2_text(test::kLayerBody, "nav2_costmap_2d::VoxelLayer"), "stvl_layer");
  EXPECT_EQ(message,
            "FILE:7: stvl_layer.plugin: plugin is 'nav2_costmap_2d::VoxelLayer', not "
            "spatio_temporal_voxel_layer/SpatioTemporalVoxelLayer");
  EXPECT_THAT(error(test::nav2_text(test::kLayerBody, "nav2_costmap_2d::VoxelLayer")), HasSubstr("no STVL layer"));
}

// nav2 runs a layer listed in `plugins` without a mapping of its own (its defaults; inflation_layer often is): the
// file is read, and the message lists it, not yaml-cpp's "invalid node".
TEST_F(RosParams, ALayerListedWithoutItsMappingIsListedNotACrash) {
  const std::string text =
      "local_costmap:\n  local_costmap:\n    ros__parameters:\n      plugins: [\"voxel_layer\", "
      "\"inflation_layer\"]\n      voxel_layer:\n        plugin: \"nav2_costmap_2d::VoxelLayer\"\n";
  const std::string message = error(text);
  EXPECT_THAT(message, HasSubstr("no STVL layer"));
  EXPECT_THAT(message, HasSubstr("voxel_layer in local_costmap (nav2_costmap_2d::VoxelLayer)"));
  EXPECT_THAT(message, HasSubstr("inflation_layer in local_costmap"));
  EXPECT_THAT(message, Not(HasSubstr("invalid node")));
  EXPECT_THAT(message,
              HasSubstr("nav2's VoxelLayer and ObstacleLayer run in `stvl-bench run` (map.ros_params), not here"));
  const std::string stvl =
      "local_costmap:\n  local_costmap:\n    ros__parameters:\n      plugins: [stvl_layer, "
      "inflation_layer]\n      stvl_layer:\n" +
      test::indented(std::string("plugin: spatio_temporal_voxel_layer/SpatioTemporalVoxelLayer\n") + test::kLayerBody,
                     8);
  EXPECT_EQ(load(stvl).layer_name, "stvl_layer");
}

TEST_F(RosParams, SeveralCandidatesNeedAName) {
  const std::string two =
      "a:\n  a:\n    ros__parameters:\n      plugins: [s]\n      s:\n" +
      test::indented(std::string("plugin: spatio_temporal_voxel_layer/SpatioTemporalVoxelLayer\n") + test::kLayerBody,
                     8);
  const std::string both = two + "b:\n  b:" + two.substr(two.find("\n    ros__parameters"));
  EXPECT_THAT(error(both, "s"), HasSubstr("layer 's' is in several costmaps"));
  EXPECT_EQ(load(both, "s", "b").costmap_name, "b");
}

TEST_F(RosParams, SourceWithoutMappingNamesObservationSources) {
  const std::string message = error("voxel_decay: 15.0\nobservation_sources: cam other\ncam: {}\n");
  EXPECT_EQ(message, "FILE:2: observation_sources: source 'other' has no mapping other");
}

// model_type 1 is STVL's 3D lidar clearing model (on a camera's cloud, as STVL would build it); 2 is no model.
TEST_F(RosParams, ModelTypeOneIsTheLidarModelTwoAndLaserScanAreErrors) {
  const RosStvlLayer lidar = load(
      "voxel_decay: 15.0\nobservation_sources: c\nc:\n  model_type: 1\n"
      "  vertical_fov_padding: 0.05\n  horizontal_fov_angle: 6.2832\n");
  ASSERT_EQ(lidar.sources.size(), 1u);
  EXPECT_EQ(lidar.sources[0].stvl.model, mapping::ClearingModel::kLidar3D);
  EXPECT_DOUBLE_EQ(lidar.sources[0].stvl.vertical_fov_padding_m, 0.05);
  EXPECT_DOUBLE_EQ(lidar.sources[0].stvl.horizontal_fov_rad, 6.2832);
  EXPECT_THAT(error("voxel_decay: 15.0\nobservation_sources: c\nc:\n  horizontal_fov_angle: 6.2832\n"),
              HasSubstr("horizontal_fov_angle"));  // a depth camera's frustum stays below pi
  EXPECT_EQ(error(test::nav2_text("voxel_decay: 15.0\nobservation_sources: c\nc:\n  model_type: 2\n")),
            "FILE:11: stvl_layer.c.model_type: 2: STVL knows 0 (depth camera) and 1 (3D lidar)");
  EXPECT_THAT(error("voxel_decay: 15.0\nobservation_sources: c\nc:\n  data_type: LaserScan\n"),
              HasSubstr(":4: c.data_type: LaserScan: only depth cameras (PointCloud2) are simulated"));
}

TEST_F(RosParams, WrongTypesAndRejectedValuesNameTheKey) {
  EXPECT_THAT(error("voxel_decay: 15.0\nvoxel_size: big\nobservation_sources: c\nc: {}\n"),
              HasSubstr(":2: voxel_size: expected a number, got 'big'"));
  EXPECT_THAT(error("voxel_decay: 15.0\nobservation_sources: c\nc:\n  clearing: sometimes\n"),
              HasSubstr(":4: c.clearing: expected a boolean"));
  EXPECT_THAT(error("voxel_decay: 15.0\nobservation_sources: c\nc:\n  max_z: 7.0\n  horizontal_fov_angle: 4.0\n"),
              HasSubstr(":5: c.horizontal_fov_angle: horizontal_fov_angle = 4 is invalid: must lie in (0, pi) rad"));
  EXPECT_THAT(error("voxel_decay: 15.0\nvoxel_size: 0.001\nobservation_sources: c\nc: {}\n"),
              HasSubstr(":2: voxel_size: voxel_size = 0.001 is invalid"));
}

// STVL declares voxel_decay -1: with every decay model the voxel's time left is negative at the next update,
// which removes it before the costmap is built. The bench's map does not model that; the loader says so.
TEST_F(RosParams, NegativeVoxelDecayIsAnErrorThatSaysWhatStvlDoes) {
  EXPECT_EQ(error(test::nav2_text("observation_sources: c\nc: {}\n")),
            "FILE:6: stvl_layer.voxel_decay: absent, so STVL's default -1 s: STVL removes every voxel at the next "
            "update, before it builds the costmap, so the layer never marks a cell; the bench's map needs "
            "voxel_decay >= 0 (write e.g. voxel_decay: 15.0, STVL's example)");
  EXPECT_THAT(error("voxel_decay: -2.0\nobservation_sources: c\nc: {}\n"), HasSubstr(":1: voxel_decay: -2 s: STVL"));
}

}  // namespace
}  // namespace stvl::config

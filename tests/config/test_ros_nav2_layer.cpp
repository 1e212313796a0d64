// nav2's VoxelLayer and ObstacleLayer read from a nav2 parameter file: nav2's defaults where the file is silent,
// every key read, the binding to the cameras, the errors naming file, line and key, and the lint findings.
#include "config/ros_nav2_layer.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <string>

#include "config/scenario.hpp"

namespace stvl::config {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

std::string write_file(const std::string& name, const std::string& text) {
  const fs::path dir = fs::temp_directory_path() / ("stvl_ros_nav2_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path path = dir / name;
  std::ofstream(path) << text;
  return path.string();
}

// A local costmap with one layer of `plugin` and a source `pointcloud` on /camera/depth/points; `extra_layer` and
// `extra_source` are lines added to the layer's and the source's mapping (indented already).
std::string params(const std::string& plugin, const std::string& extra_layer = "", const std::string& extra_source = "",
                   const std::string& costmap_keys = "") {
  return "local_costmap:\n"
         "  local_costmap:\n"
         "    ros__parameters:\n" +
         costmap_keys +
         "      plugins: [\"obstacles\"]\n"
         "      obstacles:\n"
         "        plugin: \"" +
         plugin + "\"\n" + extra_layer +
         "        observation_sources: pointcloud\n"
         "        pointcloud:\n"
         "          topic: /camera/depth/points\n"
         "          data_type: PointCloud2\n" +
         extra_source;
}

std::string error_of(const std::string& path) {
  try {
    load_ros_nav2_layer(path, "", "");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

TEST(RosNav2Layer, DefaultsAreNav2s) {
  const RosNav2Layer l = load_ros_nav2_layer(write_file("d.yaml", params("nav2_costmap_2d::VoxelLayer")), "", "");
  EXPECT_EQ(l.type, layer::LayerType::kNav2Voxel);
  EXPECT_EQ(l.layer_name, "obstacles");
  EXPECT_EQ(l.costmap_name, "local_costmap");
  // Costmap2DROS's declared defaults (jazzy f4108e5)
  EXPECT_DOUBLE_EQ(l.width_m, 5.0);
  EXPECT_DOUBLE_EQ(l.resolution_m, 0.1);
  EXPECT_FALSE(l.rolling_window);
  EXPECT_DOUBLE_EQ(l.update_frequency_hz, 5.0);
  EXPECT_EQ(l.footprint_source, "nav2's default robot_radius 0.1");
  // VoxelLayer's and the source's (ObstacleLayer::onInitialize)
  EXPECT_EQ(l.params.z_voxels, 10);
  EXPECT_DOUBLE_EQ(l.params.z_resolution_m, 0.2);
  ASSERT_EQ(l.sources.size(), 1u);
  const layer::SourceConfig& s = l.sources[0].source;
  EXPECT_TRUE(s.params.marking);
  EXPECT_FALSE(s.params.clearing);
  EXPECT_DOUBLE_EQ(s.params.max_obstacle_height_m, 0.0);  // nav2's source default: keeps nothing above the floor
  EXPECT_DOUBLE_EQ(s.nav2.obstacle_max_range_m, 2.5);
  EXPECT_DOUBLE_EQ(s.nav2.raytrace_max_range_m, 3.0);
}

TEST(RosNav2Layer, KeysAreReadAndBoundToTheCamera) {
  const std::string path = write_file(
      "k.yaml",
      params("nav2_costmap_2d::ObstacleLayer", "        max_obstacle_height: 1.2\n        combination_method: 0\n",
             "          clearing: true\n          max_obstacle_height: 1.5\n          obstacle_max_range: 2.0\n"
             "          raytrace_max_range: 2.5\n          observation_persistence: 0.3\n",
             "      width: 4\n      height: 6\n      resolution: 0.05\n      rolling_window: true\n"
             "      update_frequency: 10.0\n      robot_radius: 0.3\n"));
  const RosNav2Layer l = load_ros_nav2_layer(path, "", "");
  EXPECT_EQ(l.type, layer::LayerType::kNav2Obstacle);
  EXPECT_DOUBLE_EQ(l.params.max_obstacle_height_m, 1.2);
  EXPECT_EQ(l.params.combination_method, 0);
  EXPECT_DOUBLE_EQ(l.sources[0].source.params.observation_persistence_s, 0.3);
  pipeline::PipelineConfig config;
  config.cameras[0].name = "camera";
  apply_ros_nav2_layer(l, config);
  EXPECT_EQ(config.layer_type, layer::LayerType::kNav2Obstacle);
  EXPECT_DOUBLE_EQ(config.map.voxel_size_m, 0.05);  // the costmap's resolution
  EXPECT_DOUBLE_EQ(config.map.update_frequency_hz, 10.0);
  EXPECT_DOUBLE_EQ(config.nav2_costmap.width_m, 4.0);
  EXPECT_DOUBLE_EQ(config.nav2_costmap.height_m, 6.0);
  EXPECT_TRUE(config.nav2_costmap.rolling_window);
  EXPECT_EQ(config.map.footprint_B.size(), 16u);  // nav2's circle of robot_radius
  ASSERT_EQ(config.cameras[0].sources.size(), 1u);
  EXPECT_DOUBLE_EQ(config.cameras[0].sources[0].nav2.raytrace_max_range_m, 2.5);
  EXPECT_TRUE(config.cameras[0].sources[0].params.clearing);
  config.cameras[0].name = "front";
  EXPECT_THAT(
      [&] {
        try {
          apply_ros_nav2_layer(l, config);
        } catch (const std::invalid_argument& e) {
          return std::string(e.what());
        }
        return std::string();
      }(),
      HasSubstr("bound to no camera: topic '/camera/depth/points'"));
}

TEST(RosNav2Layer, BadValuesNameFileLineAndKey) {
  const std::string voxel = "nav2_costmap_2d::VoxelLayer";
  EXPECT_THAT(error_of(write_file("z.yaml", params(voxel, "        z_voxels: 17\n"))),
              HasSubstr("z.yaml:7: obstacles.z_voxels: 17: must lie in [1, 16]"));
  EXPECT_THAT(error_of(write_file("r.yaml", params(voxel, "", "", "      resolution: 0.0\n"))),
              HasSubstr(":4: local_costmap.resolution: 0: must be > 0 m"));
  EXPECT_THAT(error_of(write_file("n.yaml", params(voxel, "", "          raytrace_max_range: .nan\n"))),
              HasSubstr("n.yaml:11: obstacles.pointcloud.raytrace_max_range: nan: must be finite and >= 0"));
  EXPECT_THAT(error_of(write_file("m.yaml", params(voxel, "", "          obstacle_min_range: -0.5\n"))),
              HasSubstr("obstacle_min_range: -0.5: must be finite and >= 0"));
  const std::string laser = params(voxel);
  EXPECT_THAT(error_of(write_file("l.yaml", laser.substr(0, laser.find("          data_type")))),
              HasSubstr("l.yaml:9: obstacles.pointcloud.data_type: LaserScan is not simulated"));  // nav2's default
  std::string range = params(voxel);
  range.replace(range.find("PointCloud2"), 11, "Range");
  EXPECT_THAT(error_of(write_file("t.yaml", range)), HasSubstr("nav2 reads only PointCloud2 or LaserScan"));
}

TEST(RosNav2Layer, LintFindsWhatNav2StartsWithAnyway) {
  const std::string path = write_file(
      "lint.yaml",
      params("nav2_costmap_2d::VoxelLayer", "        z_voxels: 16\n        z_resolution: 0.05\n        z_voxel: 3\n",
             "          raytrace_max_range: 2.0\n          marking: true\n          clearing: true\n"
             "          inf_is_valid: true\n          obstacle_range: 3.0\n",
             "      width: 3\n      height: 3\n      rolling_window: true\n"));
  const auto findings = lint_ros_nav2_layer(path, "", "");
  std::string all;
  for (const auto& f : findings) all += format_finding(f) + "\n";
  EXPECT_THAT(all, HasSubstr("obstacles.z_voxel: nav2's nav2_costmap_2d::VoxelLayer does not read it; write instead: "
                             "z_voxels"));
  EXPECT_THAT(all, HasSubstr("pointcloud.obstacle_range: nav2's nav2_costmap_2d::VoxelLayer does not read it; write "
                             "instead: obstacle_max_range"));
  EXPECT_THAT(all, HasSubstr("raytrace_max_range 2 m < obstacle_max_range 2.5 m: obstacles marked beyond it are never "
                             "cleared"));
  EXPECT_THAT(all, HasSubstr("= 0.8 m, under max_obstacle_height 2 m"));
  EXPECT_THAT(all, HasSubstr("absent, so nav2's default 0 m: the buffer keeps no point above 0 m"));
  EXPECT_THAT(all, HasSubstr("2.5 m reaches past the rolling window's half width 1.5 m"));
  EXPECT_THAT(all, HasSubstr("inf_is_valid: no effect on a PointCloud2 source"));
  // A file written as nav2 wants it has none.
  const std::string clean =
      write_file("clean.yaml", params("nav2_costmap_2d::ObstacleLayer", "",
                                      "          max_obstacle_height: 2.0\n          clearing: true\n",
                                      "      width: 6\n      height: 6\n      rolling_window: true\n"));
  EXPECT_TRUE(lint_ros_nav2_layer(clean, "", "").empty()) << format_finding(lint_ros_nav2_layer(clean, "", "")[0]);
}

TEST(RosNav2Layer, AScenarioRunsTheFilesLayer) {
  const Scenario s = load_scenario(std::string(STVL_SOURCE_DIR) + "/scenarios/nav2_voxel_layer.yaml");
  EXPECT_EQ(s.pipeline.layer_type, layer::LayerType::kNav2Voxel);
  EXPECT_EQ(s.pipeline.nav2_layer.z_voxels, 16);
  EXPECT_DOUBLE_EQ(s.pipeline.nav2_costmap.width_m, 3.0);
  EXPECT_DOUBLE_EQ(s.pipeline.map.update_frequency_hz, 5.0);
  EXPECT_DOUBLE_EQ(s.pipeline.cameras[0].sources[0].params.min_obstacle_height_m, 0.1);
  EXPECT_THAT(s.footprint_source, HasSubstr("robot_radius"));
  EXPECT_TRUE(evaluation_config(s).layer_has_voxels);
}

}  // namespace
}  // namespace stvl::config

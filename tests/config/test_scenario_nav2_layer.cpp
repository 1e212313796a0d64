// A scenario's map.layer_type (stvl | nav2_voxel | nav2_obstacle), map.nav2_layer and the sources' nav2 ranges:
// read into the pipeline's config with nav2's defaults, the evaluation following the layer, and the errors naming the
// file, line and key.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "config/scenario.hpp"
#include "tests/config/scenario_texts.hpp"

namespace stvl::config {
namespace {

using ::testing::HasSubstr;
using namespace test;

std::string with_map(const std::string& map_block) { return std::string(kMinimal) + "map:\n" + map_block; }

TEST(ScenarioNav2Layer, DefaultsAreStvlAndNav2sLayerKeys) {
  const Scenario s = parse(kMinimal);
  EXPECT_EQ(s.pipeline.layer_type, layer::LayerType::kStvl);
  const Scenario v = parse(with_map("  layer_type: nav2_voxel\n"));
  EXPECT_EQ(v.pipeline.layer_type, layer::LayerType::kNav2Voxel);
  // VoxelLayer::onInitialize's defaults (jazzy f4108e5)
  EXPECT_EQ(v.pipeline.nav2_layer.z_voxels, 10);
  EXPECT_DOUBLE_EQ(v.pipeline.nav2_layer.z_resolution_m, 0.2);
  EXPECT_EQ(v.pipeline.nav2_layer.unknown_threshold, 15);
  EXPECT_DOUBLE_EQ(v.pipeline.nav2_layer.max_obstacle_height_m, 2.0);
  EXPECT_DOUBLE_EQ(v.pipeline.cameras[0].sources[0].nav2.obstacle_max_range_m, 2.5);
  EXPECT_DOUBLE_EQ(v.pipeline.cameras[0].sources[0].nav2.raytrace_max_range_m, 3.0);
}

TEST(ScenarioNav2Layer, LayerKeysAndRangesAreRead) {
  const Scenario s = parse(with_map(
      "  layer_type: nav2_obstacle\n  voxel_size: 0.05\n  nav2_layer:\n    z_voxels: 16\n    z_resolution: 0.05\n"
      "    origin_z: 0.1\n    mark_threshold: 2\n    max_obstacle_height: 1.5\n    combination_method: 2\n"
      "    footprint_clearing_enabled: false\n    nav2_marking_range: pre_5697\n  observation:\n"
      "    obstacle_max_range: 1.5\n    raytrace_max_range: 2.0\n    raytrace_min_range: 0.2\n"
      "  nav2_costmap: {width_m: 3, height_m: 4}\n"));
  const layer::Nav2LayerParams& n = s.pipeline.nav2_layer;
  EXPECT_EQ(n.z_voxels, 16);
  EXPECT_DOUBLE_EQ(n.origin_z_m, 0.1);
  EXPECT_EQ(n.mark_threshold, 2);
  EXPECT_EQ(n.combination_method, 2);
  EXPECT_FALSE(n.footprint_clearing_enabled);
  EXPECT_EQ(n.marking_range, layer::nav2::MarkingRange::kWorld3d);
  const layer::Nav2SourceRanges& r = s.pipeline.cameras[0].sources[0].nav2;
  EXPECT_DOUBLE_EQ(r.obstacle_max_range_m, 1.5);
  EXPECT_DOUBLE_EQ(r.raytrace_max_range_m, 2.0);
  EXPECT_DOUBLE_EQ(r.raytrace_min_range_m, 0.2);
  EXPECT_DOUBLE_EQ(s.pipeline.nav2_costmap.resolution_m, 0.05);  // the layer's one resolution: map.voxel_size
  // The evaluation follows the layer: no voxels, nav2's range and band, its footprint clearing.
  const evaluation::EvaluationConfig e = evaluation_config(s);
  EXPECT_FALSE(e.layer_has_voxels);
  EXPECT_FALSE(e.costmap_projected);
  EXPECT_TRUE(e.nav2_marking_range);
  EXPECT_DOUBLE_EQ(e.max_obstacle_height_m, 1.5);
  EXPECT_FALSE(e.footprint_clearing);
}

TEST(ScenarioNav2Layer, TheVoxelLayersGridTopBoundsTheEvaluatedBand) {
  // 16 levels of 0.05 m from 0: the grid ends at 0.8 m, under the layer's max_obstacle_height 2.0
  const Scenario s = parse(with_map("  layer_type: nav2_voxel\n  nav2_layer: {z_voxels: 16, z_resolution: 0.05}\n"));
  EXPECT_DOUBLE_EQ(evaluation_config(s).max_obstacle_height_m, 0.8);
  EXPECT_TRUE(evaluation_config(s).layer_has_voxels);
}

TEST(ScenarioNav2Layer, BadValuesNameTheKeyAndLine) {
  EXPECT_THAT(error_of(with_map("  layer_type: nav2_voxels\n")),
              HasSubstr("map.layer_type: layer_type 'nav2_voxels': expected stvl, nav2_voxel or nav2_obstacle"));
  EXPECT_THAT(error_of(with_map("  layer_type: nav2_voxel\n  nav2_layer:\n    z_voxels: 17\n")),
              HasSubstr(at(9, "map.nav2_layer.z_voxels") + "nav2_layer.z_voxels = 17: must lie in [1, 16]"));
  EXPECT_THAT(error_of(with_map("  nav2_layer:\n    z_voxels: 8\n")),
              HasSubstr("needs map.layer_type nav2_voxel or nav2_obstacle"));
  EXPECT_THAT(error_of(with_map("  layer_type: nav2_voxel\n  nav2_layer:\n    z_voxel: 8\n")),
              HasSubstr(at(9, "map.nav2_layer.z_voxel") + "unknown key"));
  EXPECT_THAT(error_of(with_map("  layer_type: nav2_voxel\n  observation:\n    raytrace_max_range: -1\n")),
              HasSubstr(at(9, "map.observation.raytrace_max_range")));
  EXPECT_THAT(error_of(with_map("  layer_type: nav2_voxel\n  observation:\n    obstacle_max_range: .nan\n")),
              HasSubstr(at(9, "map.observation.obstacle_max_range")));
  EXPECT_THAT(error_of(with_map("  layer_type: nav2_voxel\n  nav2_costmap: {width_m: 3, height_m: 3, "
                                "resolution_m: 0.1}\n")),
              HasSubstr("must equal map.voxel_size"));
  EXPECT_THAT(error_of(with_map("  layer_type: nav2_obstacle\n  nav2_layer: {nav2_marking_range: 5476}\n")),
              HasSubstr("expected pre_5697, 5697 or 6092"));
}

}  // namespace
}  // namespace stvl::config

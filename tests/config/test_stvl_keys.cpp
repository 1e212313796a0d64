// The one table of STVL's keys: the readers take exactly its rows.
#include "config/stvl_keys.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "config/ros_params_detail.hpp"

namespace stvl::config {
namespace {

using ::testing::Contains;
using ::testing::Not;

TEST(StvlKeys, NamesAreUniquePerScope) {
  std::set<std::string> layer, source;
  for (const StvlKey& k : stvl_keys()) {
    auto& names = k.scope == StvlScope::kLayer ? layer : source;
    EXPECT_TRUE(names.insert(k.name).second) << k.name << " appears twice in its scope";
    EXPECT_FALSE(k.number && k.flag) << k.name << " sets two fields";
    if (k.number) EXPECT_TRUE(k.is_double()) << k.name << " is a number without a unit";
  }
}

TEST(StvlKeys, RosVersionsReadTheirOwnKeys) {
  const auto& ros2_layer = ros_detail::layer_keys(RosFlavour::kRos2);
  const auto& ros1_layer = ros_detail::layer_keys(RosFlavour::kRos1);
  EXPECT_THAT(ros2_layer, Contains("plugin"));
  EXPECT_THAT(ros2_layer, Not(Contains("obstacle_range")));  // per source in ROS 2
  EXPECT_THAT(ros1_layer, Contains("obstacle_range"));       // searchParam() on ROS 1
  EXPECT_THAT(ros1_layer, Not(Contains("plugin")));
  EXPECT_THAT(ros_detail::source_keys(RosFlavour::kRos2), Not(Contains("voxel_filter")));
  EXPECT_THAT(ros_detail::source_keys(RosFlavour::kRos1), Contains("voxel_filter"));
  EXPECT_THAT(ros_detail::source_keys(RosFlavour::kRos2), Not(Contains("clear_on_no_return")));  // ours
}

TEST(StvlKeys, ReadSourceKeysSetsEveryFieldOfTheTable) {
  std::string text;
  for (const StvlKey& k : stvl_keys())
    if (k.scope == StvlScope::kSource && (k.number || k.flag))
      text += std::string(k.name) + ": " + (k.number ? "0.25" : "true") + "\n";
  YamlMap map(load_yaml_string(text, "keys.yaml"), "keys.yaml", "");
  mapping::ObservationSource source;
  source.marking = false, source.clearing = false;
  read_source_keys(map, source, kReadByScenario);
  for (const StvlKey& k : stvl_keys()) {
    if (k.scope != StvlScope::kSource) continue;
    if (k.number) EXPECT_DOUBLE_EQ(source.*k.number, 0.25) << k.name;
    if (k.flag) EXPECT_TRUE(source.*k.flag) << k.name;
  }
  map.finish();  // every key of the text was read
}

TEST(StvlKeys, SkippedKeysAreLeftToTheCaller) {
  YamlMap map(load_yaml_string("max_z: 4.0\nmin_z: 0.2\n", "skip.yaml"), "skip.yaml", "");
  mapping::ObservationSource source;
  const double before = source.max_z_m;
  read_source_keys(map, source, kReadByRos2, {"max_z"});
  EXPECT_EQ(source.max_z_m, before);
  EXPECT_DOUBLE_EQ(source.min_z_m, 0.2);
}

TEST(StvlKeys, DoubleKeysHaveUnits) {
  const auto names = stvl_double_key_names(StvlScope::kSource, kReadByRos2);
  EXPECT_THAT(names, Contains("max_z"));
  EXPECT_THAT(names, Contains("vertical_fov_padding"));
  EXPECT_THAT(names, Not(Contains("marking")));
  EXPECT_THAT(names, Not(Contains("voxel_min_points")));  // an int in STVL
}

}  // namespace
}  // namespace stvl::config

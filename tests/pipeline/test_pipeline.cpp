// The pipeline on a tiny world of its own: the shipped robot on a floor, facing a wall 2 m ahead.
#include "pipeline/pipeline.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace stvl::pipeline {
namespace {

using ::testing::HasSubstr;

// wall: x 2.5..2.7, y -2..2, z 0..1.5.
constexpr const char* kWorld = R"(
<mujoco>
  <compiler autolimits="true"/>
  <option timestep="0.002"/>
  <include file="robot.xml"/>
  <worldbody>
    <geom name="floor" type="plane" size="6 6 0.1"/>
    <body name="wall" pos="2.6 0 0.75"><geom type="box" size="0.1 2 0.75"/></body>
  </worldbody>
</mujoco>)";

class PipelineTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // The robot's include resolves against the world file's folder: write the world next to robot.xml's copy.
    dir_ = std::filesystem::temp_directory_path() / ("stvl_pipeline_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    std::filesystem::copy_file(std::string(STVL_SOURCE_DIR) + "/worlds/robot.xml", dir_ / "robot.xml",
                               std::filesystem::copy_options::overwrite_existing);
    std::ofstream(dir_ / "wall.xml") << kWorld;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  PipelineConfig config() const {
    PipelineConfig c;
    c.world_path = (dir_ / "wall.xml").string();
    c.path.waypoints_W = {{0.0, 0.0}, {1.0, 0.0}};
    c.path.cruise_speed_mps = 0.3;
    CameraConfig& camera = c.cameras.front();
    camera.intrinsics = sensors::CameraIntrinsics::from_hfov(160, 120, 1.2, 0.2, 6.0, 10.0);
    camera.noise.enabled = false;
    camera.source.clearing = true;
    camera.source.obstacle_range_m = 4.0;
    camera.source.min_obstacle_height_m = 0.1;
    camera.source.max_obstacle_height_m = 1.2;
    camera.source.horizontal_fov_rad = camera.intrinsics.hfov_rad();
    camera.source.vertical_fov_rad = camera.intrinsics.vfov_rad();
    c.sim.camera_mount.height_m = 0.5;
    c.filter.type = filter::FilterType::kVoxel;
    c.filter.device = filter::Device::kCpu;
    c.filter.passthrough_enabled = true;
    c.filter.passthrough = {0.1, 1.2};
    c.filter.voxel.voxel_size_m = 0.05;
    c.map.voxel_size_m = 0.05;
    return c;
  }

  std::filesystem::path dir_;
};

TEST_F(PipelineTest, FramesAtTheCameraRateThroughEveryStage) {
  Pipeline pipeline(config());
  EXPECT_EQ(pipeline.next_time_s(), 0.0);
  for (int k = 0; k < 4; ++k) {
    const FrameResult& f = pipeline.step();
    EXPECT_EQ(f.frame_index, static_cast<std::size_t>(k));
    EXPECT_DOUBLE_EQ(f.time_s, k * (1.0 / 10.0));
    EXPECT_EQ(f.camera, "camera");
    EXPECT_TRUE(f.robot_upright);
    // The wall fills the view: most pixels are valid, and the cloud lies on its face (x = 2.5 m).
    ASSERT_GT(f.point_count, 160 * 120 / 2);
    EXPECT_EQ(f.cloud_W.cols(), f.point_count);
    EXPECT_NEAR(f.cloud_W.row(0).maxCoeff(), 2.5, 0.02);
    EXPECT_GT(f.decimated_W.cols(), 0);
    EXPECT_LT(f.decimated_W.cols(), f.point_count);
    // The marking cloud is the decimated one inside the passthrough band.
    EXPECT_LT(f.marking_W.cols(), f.decimated_W.cols());
    EXPECT_GE(f.marking_W.row(2).minCoeff(), 0.1);
    EXPECT_LE(f.marking_W.row(2).maxCoeff(), 1.2);
    EXPECT_GT(f.times.render_ms, 0.0);
  }
  EXPECT_DOUBLE_EQ(pipeline.next_time_s(), 4 * (1.0 / 10.0));
  EXPECT_GT(pipeline.map().size(), 100u);
  // The costmap is lethal along the wall's face only (cells of x 2.45..2.55).
  const mapping::Costmap2D costmap = pipeline.costmap();
  int lethal = 0;
  for (int iy = 0; iy < costmap.height; ++iy)
    for (int ix = 0; ix < costmap.width; ++ix)
      if (costmap.at(ix, iy) == mapping::kCostLethal) {
        ++lethal;
        EXPECT_NEAR(costmap.origin_m.x() + (ix + 0.5) * costmap.resolution_m, 2.5, 0.051) << ix << " " << iy;
      }
  EXPECT_GT(lethal, 10);
}

TEST_F(PipelineTest, TheHookSeesTheMapBeforeTheFramesUpdate) {
  Pipeline pipeline(config());
  std::vector<std::size_t> before;
  for (int k = 0; k < 3; ++k) {
    pipeline.step([&](const FrameResult& f, const mapping::VoxelMap& map) {
      EXPECT_EQ(f.frame_index, static_cast<std::size_t>(k));
      before.push_back(map.size());
    });
  }
  EXPECT_EQ(before[0], 0u);  // nothing marked before the first frame
  EXPECT_GT(before[1], 0u);
}

TEST_F(PipelineTest, SameConfigSameMap) {
  PipelineConfig c = config();
  c.cameras.front().noise.enabled = true;
  Pipeline a(c), b(c);
  for (int k = 0; k < 3; ++k) {
    a.step();
    b.step();
  }
  const auto va = a.map().voxels(), vb = b.map().voxels();
  ASSERT_EQ(va.size(), vb.size());
  for (std::size_t i = 0; i < va.size(); ++i) EXPECT_TRUE(va[i].key == vb[i].key && va[i].time_s == vb[i].time_s);
}

TEST_F(PipelineTest, BadConfigsAreRejectedBeforeAnyFrame) {
  PipelineConfig none = config();
  none.cameras.clear();
  EXPECT_THROW(Pipeline{none}, std::invalid_argument);
  PipelineConfig two = config();
  two.cameras.push_back(two.cameras.front());
  try {
    Pipeline pipeline(two);
    ADD_FAILURE() << "two cameras accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("2 cameras"));
  }
  PipelineConfig far = config();
  far.path.waypoints_W.back() = {1e308, 0.0};
  try {
    Pipeline pipeline(far);
    ADD_FAILURE() << "a waypoint at 1e308 m accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("robot.waypoints[1]"));
    EXPECT_THAT(e.what(), HasSubstr("outside the world's extent, x -6 .. 6 m"));
  }
}

TEST(Decimation, ThePassthroughAppliesToMarkingOnly) {
  filter::FilterConfig c;
  c.type = filter::FilterType::kPassthrough;
  c.passthrough_enabled = true;
  const filter::FilterConfig d = decimation_config(c);
  EXPECT_EQ(d.type, filter::FilterType::kNone);
  EXPECT_FALSE(d.passthrough_enabled);
  c.type = filter::FilterType::kCsnb;
  EXPECT_EQ(decimation_config(c).type, filter::FilterType::kCsnb);
}

}  // namespace
}  // namespace stvl::pipeline

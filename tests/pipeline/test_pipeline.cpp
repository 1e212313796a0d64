// The pipeline on the fixture's tiny world: the shipped robot on a floor, facing a wall 2.5 m ahead; its frames
// fed to STVL's layer as the frame loop (run/) does.
#include "pipeline/pipeline.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "layer/stvl_layer.hpp"
#include "tests/support/fixture.hpp"

namespace stvl::pipeline {
namespace {

using ::testing::HasSubstr;

// The pipeline's frames into STVL's layer, one observation per step, as the frame loop feeds it.
class Driven {
 public:
  explicit Driven(const PipelineConfig& config) : pipeline_(config), layer_(layer_config(config)) {}
  const Frame& step() {
    const Frame& f = pipeline_.step();
    layer_.update(f.observation, f.cameras_now, report_);
    return f;
  }
  // A step, then the readings its update applied again.
  std::size_t step_reapplied() {
    step();
    return report_.reapplied_readings;
  }
  const layer::UpdateReport& report() const { return report_; }
  const mapping::VoxelMap& map() const { return layer_.voxels(); }
  mapping::Costmap2D costmap() const { return layer_.costmap(); }
  std::vector<layer::SourceStatus> source_status(double until_s) const { return layer_.source_status(until_s); }
  Pipeline& pipeline() { return pipeline_; }

 private:
  Pipeline pipeline_;
  layer::StvlLayer layer_;
  layer::UpdateReport report_;
};

// The shared world of the shipped robot between two walls (tests/support/fixture.hpp): wall x 2.5..2.7,
// y -2..2, z 0..1.5; back_wall x -2.7..-2.5 (behind the robot).
class PipelineTest : public test::MujocoTest {
 protected:
  PipelineConfig config() const {
    PipelineConfig c;
    c.world_path = world_.path();
    c.path.waypoints_W = {{0.0, 0.0}, {1.0, 0.0}};
    c.path.cruise_speed_mps = 0.3;
    CameraConfig& camera = c.cameras.front();
    camera.intrinsics = sensors::CameraIntrinsics::from_hfov(160, 120, 1.2, 0.2, 6.0, 10.0);
    camera.noise.enabled = false;
    camera.sources.front().params.clearing = true;
    camera.sources.front().params.obstacle_range_m = 4.0;
    camera.sources.front().params.min_obstacle_height_m = 0.1;
    camera.sources.front().params.max_obstacle_height_m = 1.2;
    camera.sources.front().params.horizontal_fov_rad = camera.intrinsics.hfov_rad();
    camera.sources.front().params.vertical_fov_rad = camera.intrinsics.vfov_rad();
    c.sim.camera_mount.height_m = 0.5;
    c.filter.type = filter::FilterType::kVoxel;
    c.filter.device = filter::Device::kCpu;
    c.filter.passthrough_enabled = true;
    c.filter.passthrough = {0.1, 1.2};
    c.filter.voxel.voxel_size_m = 0.05;
    c.map.voxel_size_m = 0.05;
    return c;
  }

  // The robot's include resolves against the world file's folder: the fixture writes it beside robot.xml's copy.
  test::WorldFile world_{"wall.xml", test::kRobotBetweenWallsWorld};
};

TEST_F(PipelineTest, FramesAtTheCameraRateThroughEveryStage) {
  Driven driven(config());
  Pipeline& pipeline = driven.pipeline();
  EXPECT_EQ(pipeline.next_time_s(), 0.0);
  for (int k = 0; k < 4; ++k) {
    const Frame& f = driven.step();
    EXPECT_EQ(f.frame_index, static_cast<std::size_t>(k));
    EXPECT_DOUBLE_EQ(f.time_s, k * (1.0 / 10.0));
    EXPECT_EQ(f.camera, "camera");
    EXPECT_TRUE(f.robot_upright);
    // The wall fills the view: most pixels are valid, and the cloud lies on its face (x = 2.5 m).
    ASSERT_GT(f.point_count, 160 * 120 / 2);
    EXPECT_EQ(f.cloud_W.cols(), f.point_count);
    EXPECT_NEAR(f.cloud_W.row(0).maxCoeff(), 2.5, 0.02);
    const layer::Observation& o = *f.observation;
    EXPECT_EQ(o.time_s, f.time_s);
    EXPECT_TRUE(o.T_world_camera.isApprox(f.T_world_camera, 0.0));
    EXPECT_GT(o.decimated_W.cols(), 0);
    EXPECT_LT(o.decimated_W.cols(), f.point_count);
    // The marking cloud is the decimated one inside the passthrough band.
    EXPECT_LT(o.marking_W.cols(), o.decimated_W.cols());
    EXPECT_GE(o.marking_W.row(2).minCoeff(), 0.1);
    EXPECT_LE(o.marking_W.row(2).maxCoeff(), 1.2);
    EXPECT_GT(f.times.render_ms, 0.0);
    // The layer took this frame's observation, once.
    ASSERT_EQ(driven.report().updates.size(), 1u);
    ASSERT_EQ(driven.report().updates[0].applied_readings.size(), 1u);
    EXPECT_EQ(driven.report().updates[0].applied_readings[0].reading, f.observation);
  }
  EXPECT_DOUBLE_EQ(pipeline.next_time_s(), 4 * (1.0 / 10.0));
  EXPECT_GT(driven.map().size(), 100u);
  // The costmap is lethal along the wall's face only (cells of x 2.45..2.55).
  const mapping::Costmap2D costmap = driven.costmap();
  int lethal = 0;
  for (int iy = 0; iy < costmap.height; ++iy)
    for (int ix = 0; ix < costmap.width; ++ix)
      if (costmap.at(ix, iy) == mapping::kCostLethal) {
        ++lethal;
        EXPECT_NEAR(costmap.origin_m.x() + (ix + 0.5) * costmap.resolution_m, 2.5, 0.051) << ix << " " << iy;
      }
  EXPECT_GT(lethal, 10);
}

// The frame gives every camera's state at that moment: its optical frame now and when its next frame is due.
TEST_F(PipelineTest, EachFrameSaysWhereEveryCameraStandsAndWhenItsNextFrameIsDue) {
  PipelineConfig c = config();
  c.cameras.push_back(c.cameras.front());
  c.cameras.back().name = c.cameras.back().sources.front().name = "slow";
  c.cameras.back().intrinsics.rate_hz = 5.0;
  Pipeline pipeline(c);
  const Frame& first = pipeline.step();  // camera 0 at 0: next 0.1; camera 1 still due at 0
  ASSERT_EQ(first.cameras_now.size(), 2u);
  EXPECT_NEAR(first.cameras_now[0].next_frame_time_s, 0.1, 1e-12);
  EXPECT_EQ(first.cameras_now[1].next_frame_time_s, 0.0);
  EXPECT_TRUE(first.cameras_now[0].T_world_camera.isApprox(first.T_world_camera, 0.0));
  const Frame& second = pipeline.step();  // camera 1 at 0: next 0.2
  EXPECT_EQ(second.camera_index, 1u);
  EXPECT_NEAR(second.cameras_now[1].next_frame_time_s, 0.2, 1e-12);
  EXPECT_TRUE(second.cameras_now[1].T_world_camera.isApprox(second.T_world_camera, 0.0));
}

TEST_F(PipelineTest, SameConfigSameMap) {
  PipelineConfig c = config();
  c.cameras.front().noise.enabled = true;
  Driven a(c), b(c);
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
  const auto error_of = [](const PipelineConfig& c) -> std::string {
    try {
      Pipeline pipeline(c);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "accepted";
  };
  PipelineConfig twins = config();
  twins.cameras.push_back(twins.cameras.front());
  EXPECT_THAT(error_of(twins), HasSubstr("camera 'camera': two cameras have this name"));
  twins.cameras.back().name = "other";
  EXPECT_THAT(error_of(twins), HasSubstr("observation source 'camera': the name is used twice"));
  PipelineConfig inside = config();
  inside.cameras.front().mount = {0.15, 0.0, 0.0};  // in the base's shell (cylinder r 0.225, z 0.04..0.24)
  EXPECT_THAT(error_of(inside), HasSubstr("camera 'camera': mounted inside the robot's body (geom 'base_shell')"));
  PipelineConfig below = config();
  below.cameras.front().mount.height_m = -0.05;
  EXPECT_THAT(error_of(below), HasSubstr("camera 'camera': mounted below the floor"));
  PipelineConfig deaf = config();
  deaf.cameras.front().sources.clear();
  EXPECT_THAT(error_of(deaf), HasSubstr("camera 'camera': feeds no observation source"));
  PipelineConfig bad_source = config();
  bad_source.cameras.front().sources.front().params.max_z_m = -1;
  EXPECT_THAT(error_of(bad_source), HasSubstr("camera 'camera', source 'camera': "));
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

CameraConfig looking_back(CameraConfig camera) {
  camera.name = "back";
  camera.sources.front().name = "back";
  camera.mount.forward_offset_m = -0.1;
  camera.mount.yaw_rad = M_PI;
  return camera;
}

TEST_F(PipelineTest, CamerasAtTheirOwnRatesInterleaveInSimulatedTime) {
  PipelineConfig c = config();
  c.cameras.push_back(looking_back(c.cameras.front()));
  c.cameras.back().intrinsics.rate_hz = 5.0;
  Driven pipeline(c);
  // Ties go to the lower index: front 0, back 0, front 0.1, front 0.2, back 0.2, front 0.3.
  const std::vector<std::pair<std::string, double>> expected{{"camera", 0.0}, {"back", 0.0}, {"camera", 0.1},
                                                             {"camera", 0.2}, {"back", 0.2}, {"camera", 0.3}};
  for (const auto& [name, time_s] : expected) {
    const Frame& f = pipeline.step();
    EXPECT_EQ(f.camera, name);
    EXPECT_NEAR(f.time_s, time_s, 1e-12);
    ASSERT_GT(f.point_count, 0);
    // Each camera sees its own wall: the front one's face at x = 2.5, the back one's at x = -2.5.
    const double face_x = name == "back" ? -2.5 : 2.5;
    EXPECT_NEAR(name == "back" ? f.cloud_W.row(0).minCoeff() : f.cloud_W.row(0).maxCoeff(), face_x, 0.05);
  }
  EXPECT_EQ(pipeline.step().camera, "camera");  // 0.4 (front) before 0.4 (back)
  int front = 0, back = 0;
  const mapping::Costmap2D costmap = pipeline.costmap();
  for (int iy = 0; iy < costmap.height; ++iy)
    for (int ix = 0; ix < costmap.width; ++ix)
      if (costmap.at(ix, iy) == mapping::kCostLethal) {
        const double x = costmap.origin_m.x() + (ix + 0.5) * costmap.resolution_m;
        front += std::abs(x - 2.5) < 0.06;
        back += std::abs(x + 2.5) < 0.06;
      }
  EXPECT_GT(front, 10);
  EXPECT_GT(back, 10);
}

// Cameras of one instant: the first step() starts the others' drawing on threads; the frames (clean and noisy
// images, poses) and the map must be those of drawing each at its own step().
TEST_F(PipelineTest, CamerasOfOneInstantDrawnTogetherGiveTheFramesOfOneAfterAnother) {
  PipelineConfig c = config();
  c.cameras.front().noise.enabled = true;
  c.cameras.push_back(looking_back(c.cameras.front()));
  CameraConfig side = c.cameras.front();
  side.name = side.sources.front().name = "side";
  side.mount.yaw_rad = 0.6;
  c.cameras.push_back(side);
  Driven together(c), apart(c);
  apart.pipeline().set_draw_ahead(false);
  for (int k = 0; k < 12; ++k) {
    const Frame& a = together.step();
    const Frame& b = apart.step();
    ASSERT_EQ(a.camera, b.camera);
    ASSERT_EQ(a.time_s, b.time_s);
    EXPECT_TRUE(a.T_world_camera.isApprox(b.T_world_camera, 0.0));
    ASSERT_GT(a.clean_depth.valid_count(), 1000);
    EXPECT_EQ(a.clean_depth.depth_m, b.clean_depth.depth_m) << "frame " << k << " of " << a.camera;
    EXPECT_EQ(a.depth.depth_m, b.depth.depth_m) << "frame " << k << " of " << a.camera;
  }
  EXPECT_EQ(together.map().voxel_keys(), apart.map().voxel_keys());
  Pipeline stopped(c);
  stopped.step();  // two draws still under way when it goes: its destructor waits for them
}

TEST_F(PipelineTest, MarkingAndClearingSourcesOnOneCameraKeepTheirOwnParameters) {
  Driven both(config());
  PipelineConfig split = config();
  SourceConfig mark = split.cameras.front().sources.front(), clear = mark;
  mark.name = "mark", mark.params.clearing = false;
  clear.name = "clear", clear.params.marking = false, clear.params.obstacle_range_m = 1.0;
  split.cameras.front().sources = {mark, clear};
  Driven separate(split);
  PipelineConfig clear_only = split;
  clear_only.cameras.front().sources = {clear};
  Driven no_marks(clear_only);
  PipelineConfig short_range = split;
  short_range.cameras.front().sources.front().params.obstacle_range_m = 2.0;  // the wall is 2.4 m away
  Driven too_short(short_range);
  for (int k = 0; k < 3; ++k) both.step(), separate.step(), no_marks.step(), too_short.step();
  // A static scene and no decay acceleration: the marking source alone decides the map.
  ASSERT_GT(both.map().size(), 100u);
  EXPECT_EQ(separate.map().voxel_keys(), both.map().voxel_keys());
  EXPECT_EQ(no_marks.map().size(), 0u);
  EXPECT_EQ(too_short.map().size(), 0u);
}

TEST_F(PipelineTest, EachCameraHasItsOwnNoise) {
  PipelineConfig c = config();
  c.cameras.front().noise.enabled = true;
  CameraConfig twin = c.cameras.front();
  twin.name = twin.sources.front().name = "twin";
  c.cameras.push_back(twin);
  Pipeline pipeline(c);
  const Frame& a = pipeline.step();
  const std::vector<float> clean_a(a.clean_depth.depth_m.begin(), a.clean_depth.depth_m.end());
  const std::vector<float> noisy_a(a.depth.depth_m.begin(), a.depth.depth_m.end());
  const Frame& b = pipeline.step();
  EXPECT_EQ(b.camera, "twin");
  EXPECT_EQ(std::vector<float>(b.clean_depth.depth_m.begin(), b.clean_depth.depth_m.end()), clean_a);  // same view
  EXPECT_NE(std::vector<float>(b.depth.depth_m.begin(), b.depth.depth_m.end()), noisy_a);              // other noise
  // Camera 0's noise is the one-camera run's.
  PipelineConfig one = config();
  one.cameras.front().noise.enabled = true;
  Pipeline alone(one);
  const Frame& solo = alone.step();
  EXPECT_EQ(std::vector<float>(solo.depth.depth_m.begin(), solo.depth.depth_m.end()), noisy_a);
}

TEST_F(PipelineTest, TheEdgeFilterThinsTheCloudNotTheCamerasImage) {
  PipelineConfig off = config();
  off.cameras.front().noise.enabled = true;
  PipelineConfig on = off;
  on.cameras.front().edge_filter.enabled = true;
  // The default (0.03 m at 1 m) is 8 sigma of the D435's stereo noise at fx = 433 px; this camera's fx is 117
  // px, so its noise is 3.7 times larger: 8 sigma of it.
  const auto& k = off.cameras.front().intrinsics;
  on.cameras.front().edge_filter.max_jump_at_1m_m =
      8.0 * on.cameras.front().noise.subpixel / (k.fx * on.cameras.front().noise.baseline_m);
  Pipeline a(off), b(on);
  const Frame& fa = a.step();
  const std::vector<float> noisy(fa.depth.depth_m.begin(), fa.depth.depth_m.end());
  const Eigen::Index points_off = fa.point_count;
  EXPECT_TRUE(fa.edge_filtered_depth.depth_m.empty());
  EXPECT_EQ(fa.edge_dropped_pixels, 0u);
  const Frame& fb = b.step();
  // The camera's image is the same; the wall and the floor are planes far from the optical centre and the view
  // has no depth edge, so 8 sigma keep nearly every pixel of the noisy image.
  EXPECT_EQ(std::vector<float>(fb.depth.depth_m.begin(), fb.depth.depth_m.end()), noisy);
  EXPECT_EQ(fb.point_count, fb.edge_filtered_depth.valid_count());
  EXPECT_EQ(fb.point_count + Eigen::Index(fb.edge_dropped_pixels), points_off);
  EXPECT_LT(double(fb.edge_dropped_pixels), 0.001 * double(points_off));
  // A threshold far below the noise drops most pixels: the cloud comes from the filtered image.
  on.cameras.front().edge_filter.max_jump_at_1m_m = 1e-4;
  Pipeline c(on);
  const Frame& fc = c.step();
  EXPECT_EQ(std::vector<float>(fc.depth.depth_m.begin(), fc.depth.depth_m.end()), noisy);
  EXPECT_GT(double(fc.edge_dropped_pixels), 0.5 * double(points_off));
  EXPECT_EQ(fc.point_count + Eigen::Index(fc.edge_dropped_pixels), points_off);
  EXPECT_EQ(fc.cloud_W.cols(), fc.point_count);
  // A bad threshold is rejected naming the camera.
  on.cameras.front().edge_filter.max_jump_at_1m_m = -1.0;
  try {
    Pipeline bad(on);
    ADD_FAILURE() << "a negative threshold was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("camera 'camera': DepthEdgeFilterConfig: max_jump_at_1m_m"));
  }
}

TEST_F(PipelineTest, NoFrameOfACameraInsideItsOutage) {
  PipelineConfig c = config();  // 10 Hz
  c.cameras.front().outages = {{0.15, 0.45}};
  c.cameras.front().sources.front().params.expected_update_rate_s = 0.2;
  Driven pipeline(c);
  std::vector<double> taken;
  for (int k = 0; k < 4; ++k) taken.push_back(pipeline.step().time_s);
  EXPECT_NEAR(taken[0], 0.0, 1e-12);
  EXPECT_NEAR(taken[1], 0.1, 1e-12);
  EXPECT_NEAR(taken[2], 0.5, 1e-12);  // 0.2, 0.3, 0.4 fall in [0.15, 0.45)
  EXPECT_NEAR(taken[3], 0.6, 1e-12);
  EXPECT_EQ(pipeline.pipeline().skipped_frames(0), 3u);
  // expected_update_rate 0.2 s: not current from 0.1 + 0.2 until the frame at 0.5.
  const auto status = pipeline.source_status(0.6);
  ASSERT_EQ(status.size(), 1u);
  ASSERT_EQ(status[0].stale.size(), 1u);
  EXPECT_NEAR(status[0].stale[0].from_s, 0.3, 1e-9);
  EXPECT_NEAR(status[0].stale[0].to_s, 0.5, 1e-9);
  // Closed at the time asked for when no frame came since.
  EXPECT_EQ(pipeline.source_status(0.9).back().stale.size(), 2u);
  EXPECT_NEAR(pipeline.source_status(0.9).back().stale.back().from_s, 0.8, 1e-9);
  // An outage at the start: the first frame comes at its end.
  PipelineConfig late = config();
  late.cameras.front().outages = {{0.0, 0.25}};
  Pipeline starts_late(late);
  EXPECT_NEAR(starts_late.next_time_s(), 0.3, 1e-12);
}

TEST_F(PipelineTest, AStoppedCamerasLastReadingIsAppliedAgainAtEveryUpdate) {
  PipelineConfig c = config();
  c.cameras.push_back(looking_back(c.cameras.front()));
  c.cameras.front().outages = {{0.15, 0.45}};  // front: 0, 0.1, then 0.5; back: every 0.1 s
  Driven pipeline(c);
  std::vector<std::pair<std::string, std::size_t>> got;
  for (int k = 0; k < 8; ++k) {
    const Frame& f = pipeline.step();
    got.emplace_back(f.camera + "@" + std::to_string(static_cast<int>(std::lround(f.time_s * 10))),
                     pipeline.report().reapplied_readings);
  }
  // STVL applies every buffer at every update: the back camera's updates at 0.2, 0.3, 0.4 apply the front's
  // reading of 0.1 again (its clouds and its frustum at the 0.1 s pose); none before the front missed a frame.
  const std::vector<std::pair<std::string, std::size_t>> expected{{"camera@0", 0}, {"back@0", 0},  {"camera@1", 0},
                                                                  {"back@1", 0},   {"back@2", 1},  {"back@3", 1},
                                                                  {"back@4", 1},   {"camera@5", 0}};
  EXPECT_EQ(got, expected);
  const auto status = pipeline.source_status(0.5);
  EXPECT_EQ(status[0].reapplied_readings, 3u);
  EXPECT_NEAR(status[0].max_reapplied_age_s, 0.3, 1e-9);
  EXPECT_GT(status[0].reapplied_max_distance_m, 0.0);  // the robot drove on: an old pose
  EXPECT_EQ(status[1].reapplied_readings, 0u);
  // Two cameras sharing frame times make one update per time: the stopped one's reading is applied once.
  PipelineConfig three = c;
  three.cameras.push_back(looking_back(c.cameras.front()));
  three.cameras.back().name = three.cameras.back().sources.front().name = "back2";
  three.cameras.back().outages.clear();
  Driven shared(three);
  std::size_t reapplied = 0;
  while (shared.pipeline().next_time_s() < 0.45) reapplied += shared.step_reapplied();
  EXPECT_EQ(reapplied, 3u);  // at 0.2, 0.3 and 0.4, not twice at each
  // drop_when_not_current (the bench's): not applied once the source is not current.
  c.cameras.front().sources.front().params.expected_update_rate_s = 0.15;
  c.cameras.front().sources.front().params.drop_when_not_current = true;
  Driven dropping(c);
  reapplied = 0;
  while (dropping.pipeline().next_time_s() < 0.45) reapplied += dropping.step_reapplied();
  EXPECT_EQ(reapplied, 1u);  // at 0.2 (0.1 s old, current); at 0.3 and 0.4 it is not
}

TEST_F(PipelineTest, ObservationPersistenceAppliesTheLastReadingsAgain) {
  PipelineConfig c = config();
  c.cameras.front().sources.front().params.observation_persistence_s = 0.25;
  Driven pipeline(c);
  const std::vector<std::size_t> expected{0, 1, 2, 2, 2};  // readings within 0.25 s of the newest
  for (std::size_t k = 0; k < expected.size(); ++k) EXPECT_EQ(pipeline.step_reapplied(), expected[k]) << k;
  Driven latest_only(config());
  for (int k = 0; k < 5; ++k) EXPECT_EQ(latest_only.step_reapplied(), 0u);
}

}  // namespace
}  // namespace stvl::pipeline

// The frame loop on frames made here (no simulator, no bag): the order of the floors, the stop rules, the series.
#include "run/frame_loop.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <string>
#include <vector>

#include "layer/stvl_layer.hpp"
#include "pipeline/sensing.hpp"
#include "tests/support/wall_frames.hpp"

namespace stvl::run {
namespace {

// Frames of a wall at 2 m every 0.1 s, sensed; frame `fall_at` (if any) has a robot that fell.
class WallFrames : public FrameSource {
 public:
  WallFrames(const pipeline::PipelineConfig& config, int count, int fall_at = -1)
      : config_(config), sensing_(config), count_(count), fall_at_(fall_at) {}
  const pipeline::Frame* next() override {
    if (taken_ >= count_) return nullptr;
    frame_ = test::wall_frame(config_, 2.0, 0.1 * taken_);
    frame_.frame_index = static_cast<std::size_t>(taken_);
    frame_.robot_upright = taken_ != fall_at_;
    sensing_.sense(frame_);
    frame_.cameras_now = {{frame_.T_world_camera, 0.1 * (taken_ + 1)}};
    ++taken_;
    return &frame_;
  }
  const std::vector<pipeline::CameraConfig>& cameras() const override { return config_.cameras; }
  std::unique_ptr<BagRecorder> open_bag(const std::string&, const BagSettings&, const pipeline::Frame*) override {
    return nullptr;
  }

 private:
  pipeline::PipelineConfig config_;
  pipeline::Sensing sensing_;
  int count_, fall_at_, taken_ = 0;
  pipeline::Frame frame_;
};

// Writes down what the loop asked of it, and ends the loop after `stop_after` frames (0: never).
class Recorder : public FrameHooks {
 public:
  explicit Recorder(std::size_t stop_after = 0) : stop_after_(stop_after) {}
  void before_update(const pipeline::Frame& f, const layer::Layer& layer) override {
    calls.push_back("before " + std::to_string(f.frame_index) + " map " + std::to_string(layer.voxels().size() > 0));
  }
  void after_update(const pipeline::Frame& f, const layer::UpdateReport& report, const layer::Layer& layer) override {
    calls.push_back("after " + std::to_string(f.frame_index) + " updates " + std::to_string(report.updates.size()) +
                    " map " + std::to_string(layer.voxels().size() > 0));
  }
  bool done(const pipeline::Frame&, const layer::UpdateReport&, std::size_t frames) override {
    return stop_after_ > 0 && frames >= stop_after_;
  }
  std::vector<std::string> calls;

 private:
  std::size_t stop_after_;
};

TEST(FrameLoop, EachFrameGoesDownTheFloorsOnceUntilTheHooksAreDone) {
  const pipeline::PipelineConfig config = test::small_config(mapping::ClearingMode::kFrustum);
  WallFrames frames(config, 5);
  layer::StvlLayer layer(pipeline::layer_config(config));
  Recorder hooks(3);
  const FrameLoopResult r = run_frame_loop(frames, layer, hooks, {});
  // The hooks see the layer before its update (empty at the first frame) and after it.
  EXPECT_EQ(hooks.calls,
            (std::vector<std::string>{"before 0 map 0", "after 0 updates 1 map 1", "before 1 map 1",
                                      "after 1 updates 1 map 1", "before 2 map 1", "after 2 updates 1 map 1"}));
  EXPECT_EQ(r.frames, 3u);
  EXPECT_DOUBLE_EQ(r.sim_time_s, 0.2);
  EXPECT_FALSE(r.fell || r.interrupted);
  for (const auto* series : {&r.times.render, &r.times.clear, &r.times.bag, &r.times.frame})
    EXPECT_EQ(series->size(), 3u);
  ASSERT_EQ(r.points_raw.size(), 3u);
  EXPECT_EQ(r.points_raw[0], 64u * 48u);
  EXPECT_EQ(r.map_voxels.back(), layer.voxels().size());
  ASSERT_EQ(r.sources.size(), 1u);
}

TEST(FrameLoop, AFallenRobotOrAStopRequestEndsTheLoopBeforeTheLayer) {
  const pipeline::PipelineConfig config = test::small_config(mapping::ClearingMode::kFrustum);
  WallFrames falls(config, 5, 2);
  layer::StvlLayer layer(pipeline::layer_config(config));
  Recorder hooks;
  const FrameLoopResult fell = run_frame_loop(falls, layer, hooks, {});
  EXPECT_TRUE(fell.fell);
  EXPECT_DOUBLE_EQ(fell.fell_at_s, 0.2);
  EXPECT_EQ(fell.frames, 2u);  // the fallen frame is neither updated nor counted
  EXPECT_EQ(hooks.calls.size(), 4u);

  WallFrames stopped(config, 5);
  layer::StvlLayer untouched(pipeline::layer_config(config));
  Recorder none;
  const std::atomic<bool> stop{true};
  FrameLoopSettings settings;
  settings.stop_requested = &stop;
  const FrameLoopResult interrupted = run_frame_loop(stopped, untouched, none, settings);
  EXPECT_TRUE(interrupted.interrupted);
  EXPECT_EQ(interrupted.frames, 0u);
  EXPECT_TRUE(none.calls.empty());
  EXPECT_TRUE(untouched.voxels().empty());
}

}  // namespace
}  // namespace stvl::run

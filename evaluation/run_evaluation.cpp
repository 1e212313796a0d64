#include "evaluation/run_evaluation.hpp"

#include <algorithm>

#include "common/stopwatch.hpp"
#include "common/units.hpp"

namespace stvl::evaluation {
namespace {

std::vector<std::vector<OutageWindow>> outage_windows(const std::vector<pipeline::CameraConfig>& cameras) {
  std::vector<std::vector<OutageWindow>> windows;
  for (const auto& c : cameras) {
    windows.emplace_back();
    for (const auto& o : c.outages) windows.back().push_back({o.from_s, o.to_s});
  }
  return windows;
}

}  // namespace

RunEvaluation::RunEvaluation(const sim::World& world, const EvaluationConfig& config, const ChecksConfig& checks,
                             const std::vector<pipeline::CameraConfig>& cameras)
    : config_(config),
      checks_(checks),
      evaluator_(world, config),
      outages_(outage_windows(cameras), config.tolerance_voxels),
      next_evaluation_s_(config.evaluate_every_s) {
  for (const auto& c : cameras) {
    camera_names_.push_back(c.name);
    intrinsics_.push_back(c.intrinsics);
    double range_m = 0.0;
    for (const auto& source : c.sources)
      if (source.params.marking)
        range_m = std::max(
            range_m, config.nav2_marking_range ? source.nav2.obstacle_max_range_m : source.params.obstacle_range_m);
    marking_range_m_.push_back(range_m);
  }
}

CameraView RunEvaluation::view_of(const pipeline::Frame& f) const {
  return CameraView{&f.clean_depth, intrinsics_[f.camera_index], f.T_world_camera, marking_range_m_[f.camera_index],
                    f.camera_index};
}

void RunEvaluation::before_update(const pipeline::Frame& f, const sim::World& world, const mapping::VoxelMap& map) {
  const auto start = SteadyClock::now();
  evaluator_.observe_clearing(f.time_s, world, view_of(f), map);
  outages_.before_update(f.time_s, map);
  before_ms_ += ms_since(start);
}

void RunEvaluation::after_update(const pipeline::Frame& f, const layer::UpdateReport& report, const sim::World& world,
                                 const mapping::VoxelMap& map) {
  const auto start = SteadyClock::now();
  const CameraView view = view_of(f);
  evaluator_.set_robot_pose(f.T_world_base);
  evaluator_.after_update(f.time_s, map, report.cleared_keys);
  evaluator_.observe_hidden_clears(f.time_s, view, map, report.cleared_keys);
  evaluator_.observe(f.time_s, view);
  outages_.after_update(f.time_s, map);
  outages_.observe(f.camera_index, f.time_s, evaluator_.frame_keys(), evaluator_.truth(),
                   static_cast<std::size_t>(f.observation->marking_W.cols()));
  if (f.time_s + kTimeEpsilon_s >= next_evaluation_s_) {
    evaluator_.evaluate(f.time_s, world, map);
    next_evaluation_s_ += config_.evaluate_every_s;
  }
  frame_ms_ = before_ms_ + ms_since(start);
  before_ms_ = 0;
}

void RunEvaluation::observe_lost(const pipeline::Frame& f, double time_s, const sim::World& world) {
  const auto start = SteadyClock::now();
  evaluator_.refresh_truth(world);  // the drive's judging reads it (a closed loop driving without frames)
  evaluator_.observe(time_s, view_of(f));
  before_ms_ += ms_since(start);  // counted with the next frame's evaluation
}

RunVerdict RunEvaluation::finish(const RunEnd& end, const sim::World& world, const mapping::VoxelMap& map) {
  RunVerdict v;
  v.checks.push_back(end.fell ? robot_upright_check(false, end.fell_at_s, end.tilt_rad)
                              : robot_upright_check(true, end.time_s, 0.0));
  if (end.path_required && !end.fell)
    v.checks.push_back(path_completed_check(end.path_done, end.time_s, end.duration_s, end.cut_short_from_s,
                                            end.path_required_when_cut_short, end.blocked));
  if (end.frames == 0) return v;
  v.evaluation = evaluator_.finish(end.time_s, world, map);
  v.top_down = evaluator_.top_down();
  v.phases = evaluator_.phase_times();
  v.map_view = make_map_view(map, evaluator_.truth(), config_.tolerance_voxels);
  v.outages = outages_.results(v.evaluation.snapshots);
  for (auto& check : evaluation_checks(checks_, v.evaluation, camera_names_)) v.checks.push_back(std::move(check));
  for (auto& check : outage_checks(checks_, v.outages, camera_names_)) v.checks.push_back(std::move(check));
  for (auto& check : soak_checks(checks_, end.soak)) v.checks.push_back(std::move(check));
  return v;
}

LethalVsTruth RunEvaluation::against_truth(const mapping::Costmap2D& costmap) const {
  return lethal_against_truth(costmap, evaluator_.truth().footprint(), config_.voxel_size_m, config_.tolerance_voxels,
                              config_.phantom_clearance_m, config_.phantom_min_cells);
}

}  // namespace stvl::evaluation

#include "evaluation/evaluator.hpp"

#include "common/stopwatch.hpp"
#include "evaluation/observe_keys.hpp"
#include "mapping/footprint.hpp"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <optional>

namespace stvl::evaluation {

EvaluationMean mean_of(const std::vector<EvaluationSnapshot>& snapshots, double warm_up_s) {
  EvaluationMean m;
  if (snapshots.empty()) return m;
  const double warm_up_end = snapshots.front().time_s + warm_up_s;
  for (const auto& s : snapshots) {
    m.max_lethal_without_voxels = std::max(m.max_lethal_without_voxels, s.projection.lethal_without_voxels);
    m.max_columns_without_lethal = std::max(m.max_columns_without_lethal, s.projection.columns_without_lethal);
    m.max_self_inside = std::max(m.max_self_inside, s.self_marking.inside);
    m.max_self_ring = std::max(m.max_self_ring, s.self_marking.ring);
    m.max_self_lethal = std::max(m.max_self_lethal, s.self_marking.total());
    if (s.path_block.cells > m.max_path_block.cells)
      m.max_path_block = s.path_block, m.max_path_block_time_s = s.time_s;
  }
  std::size_t n = 0, with_mapped = 0;
  double phantoms = 0;
  for (const auto& s : snapshots) {
    if (s.time_s < warm_up_end && snapshots.size() > 1) continue;
    ++n;
    if (s.mapped_voxels > 0) m.precision += s.precision, ++with_mapped;
    if (s.observed_truth_voxels > 0) m.recall += s.recall, m.f1 += s.f1, m.iou += s.iou;
    else ++m.empty_snapshots;
    m.costmap_precision += s.costmap_precision, m.costmap_recall += s.costmap_recall;
    m.mapped_voxels += s.mapped_voxels, m.observed_truth_voxels += s.observed_truth_voxels;
    m.lethal_cells += s.lethal_cells;
    phantoms += s.phantom_obstacles;
    m.camera_recall.resize(std::max(m.camera_recall.size(), s.cameras.size()));
    for (std::size_t c = 0; c < s.cameras.size(); ++c) m.camera_recall[c] += s.cameras[c].recall;
    m.max_phantom_obstacles = std::max(m.max_phantom_obstacles, s.phantom_obstacles);
  }
  if (n > 0) {
    const std::size_t scored = n - m.empty_snapshots;
    if (with_mapped > 0) m.precision /= with_mapped;
    if (scored > 0) m.recall /= scored, m.f1 /= scored, m.iou /= scored;
    m.costmap_precision /= n, m.costmap_recall /= n;
    m.mapped_voxels /= n, m.observed_truth_voxels /= n, m.lethal_cells /= n;
    m.phantom_obstacles = phantoms / n;
    for (double& recall : m.camera_recall) recall /= n;
  }
  m.snapshots = n;
  m.time_s = snapshots.back().time_s;
  return m;
}

Evaluator::Evaluator(const sim::World& world, const EvaluationConfig& config) : config_(config), truth_(world, config) {
  config_.validate();
  if (config_.cameras > 1) last_seen_by_camera_.resize(config_.cameras);
  update_truth(world);
}

void Evaluator::update_truth(const sim::World& world) {
  const ScopedMsTimer timer(times_.truth_ms);
  truth_.update(world);
  for (const auto* body : truth_.bodies()) {
    auto& result = obstacles_[body->body_name];
    result.name = body->body_name;
    result.truth_voxels = std::max(result.truth_voxels, body->voxels.size());
  }
}

void Evaluator::observe(double time_s, const CameraView& view) {
  const ScopedMsTimer timer(times_.observe_ms);
  if (view.camera_index >= config_.cameras)
    throw std::invalid_argument("evaluation: camera index " + std::to_string(view.camera_index) + " of " +
                                std::to_string(config_.cameras) + " cameras");
  ++times_.frames;
  observed_keys(*view.clean_depth, view.intrinsics, view.T_world_camera, view.obstacle_range_m, config_, frame_keys_);
  // Voxels last seen before the recall window are forgotten here as at an evaluation (evaluations come later).
  const double oldest_s = time_s - config_.recall_window_s;
  last_seen_.record(frame_keys_, time_s, oldest_s, [&](SeenVoxels::Entry& seen) {
    if (!seen.off_truth && body_of(seen) < 0) off_truth_keys_.insert(seen.key), seen.off_truth = true;
  });
  if (!last_seen_by_camera_.empty())
    last_seen_by_camera_[view.camera_index].record(frame_keys_, time_s, oldest_s, [](const SeenVoxels::Entry&) {});
}

int Evaluator::body_of(SeenVoxels::Entry& seen) const {
  if (seen.static_body == SeenVoxels::Entry::kUnknown) seen.static_body = truth_.static_body_of(seen.key);
  return seen.static_body >= 0 ? seen.static_body : truth_.moving_body_of(seen.key);
}

void Evaluator::observe_clearing(double time_s, const sim::World& world, const CameraView& view,
                                 const mapping::VoxelMap& map) {
  if (!truth_.has_moving_bodies()) return;
  const ScopedMsTimer timer(times_.clearing_ms);
  update_truth(world);
  stale_.update(truth_);
  // Stale voxels: in the map (as the previous update left it), where a moving body was, now far from every
  // true surface; seen through when the noise-free depth at their pixel lies beyond them. The map's voxels in
  // the candidates' box are visited (fewer than the candidates), then recorded in the vacated set's order.
  const sensors::DepthImage& depth = *view.clean_depth;
  const Eigen::Isometry3d T_camera_world = view.T_world_camera.inverse();
  std::vector<VoxelKey> seen;
  map.for_each_key_in(stale_.lo(), stale_.hi(), [&](const VoxelKey& k) {
    if (!stale_.contains(k) || clearing_.tracked(k)) return;
    const Eigen::Vector3d p_C = T_camera_world * voxel_center(k, config_.voxel_size_m);
    const auto pixel = sensors::project_to_pixel(view.intrinsics, p_C);
    if (!pixel) return;
    const int u = static_cast<int>(std::lround(pixel->x())), v = static_cast<int>(std::lround(pixel->y()));
    if (u < 0 || v < 0 || u >= depth.width || v >= depth.height) return;
    const float z = depth.at(u, v);
    if (z > 0.0f && z > p_C.z() + config_.voxel_size_m) seen.push_back(k);
  });
  sort_in_vacated_order(truth_, seen);
  for (const VoxelKey& k : seen) clearing_.seen_through(k, time_s);
}

void Evaluator::after_update(double time_s, const mapping::VoxelMap& map, const std::vector<VoxelKey>& cleared_keys) {
  {  // the next evaluation's per-voxel results, a frame's share at a time (the figures do not depend on it)
    const ScopedMsTimer timer(times_.mapped_ms);
    mapped_.update(map, truth_);
  }
  const ScopedMsTimer timer(times_.clearing_ms);
  // A true voxel the rays removed and no point marked again in the same update: gone from the map. (In frustum
  // mode cleared_keys holds what the acceleration removed: observe_hidden_clears() looks at those.)
  if (map.config().clearing_mode == mapping::ClearingMode::kRaycast)
    for (const VoxelKey& k : cleared_keys) false_clears_ += truth_.contains(k) && !map.contains(k);
  clearing_.after_update(
      time_s, [&](const VoxelKey& k) { return map.lookup(voxel_center(k, config_.voxel_size_m)).has_value(); });
}

void Evaluator::observe_hidden_clears(double time_s, const CameraView& view, const mapping::VoxelMap& map,
                                      const std::vector<VoxelKey>& cleared_keys) {
  const ScopedMsTimer timer(times_.clearing_ms);
  const double s = config_.voxel_size_m;
  hidden_clears_.after_update(
      time_s, cleared_keys, truth_.bodies(), [&](const VoxelKey& k) { return truth_.body_of(k); },
      [&](const VoxelKey& k) { return map.contains(k); },
      [&](const VoxelKey& k) { return voxel_sight(k, s, *view.clean_depth, view.intrinsics, view.T_world_camera, s); });
}

VoxelMatches Evaluator::match_mapped_voxels(const mapping::VoxelMap& map) {
  const ScopedMsTimer timer(times_.mapped_ms);
  return mapped_.match(map, truth_);  // reference::match_mapped()'s figures, kept from one evaluation to the next
}

VoxelMatches Evaluator::match_observed_truth(double time_s, std::vector<CellKey>& observed_cells) {
  const ScopedMsTimer timer(times_.observed_ms);
  VoxelMatches m;
  const auto& bodies = truth_.bodies();
  std::vector<std::size_t> body_observed(bodies.size()), body_matched(bodies.size());
  last_seen_.forget_before(time_s - config_.recall_window_s);
  for (SeenVoxels::Entry& seen : last_seen_.entries()) {
    const int body = body_of(seen);
    if (body < 0) continue;
    ++m.observed_truth;
    ++body_observed[body];
    observed_cells.push_back({seen.key.x, seen.key.y});
    if (mapped_.near(seen.key, config_.tolerance_voxels)) ++m.matched_truth, ++body_matched[body];
  }
  for (std::size_t b = 0; b < bodies.size(); ++b)
    update_obstacle(obstacles_[bodies[b]->body_name], body_observed[b], body_matched[b], config_.min_observed_voxels);
  return m;
}

std::vector<CameraRecall> Evaluator::camera_recalls(double time_s, const VoxelMatches& total) {
  const auto recall_of = [](CameraRecall r) {
    r.recall = voxel_scores({0, 0, r.observed_truth_voxels, r.matched_truth}).recall;
    return r;
  };
  if (last_seen_by_camera_.empty()) return {recall_of({total.observed_truth, total.matched_truth, 0.0})};
  std::vector<CameraRecall> recalls;
  for (SeenVoxels& camera_seen : last_seen_by_camera_) {
    CameraRecall r;
    camera_seen.forget_before(time_s - config_.recall_window_s);
    for (SeenVoxels::Entry& seen : camera_seen.entries()) {
      if (body_of(seen) < 0) continue;
      ++r.observed_truth_voxels;
      if (mapped_.near(seen.key, config_.tolerance_voxels)) ++r.matched_truth;
    }
    recalls.push_back(recall_of(r));
  }
  return recalls;
}

CellGrid Evaluator::project_lethal(const mapping::VoxelMap& map, CellGrid& columns) {
  const ScopedMsTimer timer(times_.costmap_ms);
  if (layer_costmap_) return lethal_cells(layer_costmap_(), config_.voxel_size_m);
  if (map.empty()) return {};
  mapping::CostmapOptions options;  // its band infinite unless the costmap counts the marking band only
  if (!config_.costmap_every_voxel) {
    options.min_obstacle_height_m = config_.min_obstacle_height_m;
    options.max_obstacle_height_m = config_.max_obstacle_height_m;
  }
  columns = column_counts(map, options.min_obstacle_height_m, options.max_obstacle_height_m);
  options.resolution_m = config_.voxel_size_m;
  if (config_.footprint_clearing)
    options.free_polygon_W = mapping::footprint_in_world(config_.robot_footprint_B, T_world_base_);
  return lethal_cells(map.project_costmap(options), config_.voxel_size_m);
}

void Evaluator::score_costmap(const mapping::VoxelMap& map, const CellGrid& lethal, const CellGrid& columns,
                              const CellGrid& observed_cells, EvaluationSnapshot& snap) {
  const double cell_m = config_.voxel_size_m;
  std::optional<ScopedMsTimer> timer(std::in_place, times_.costmap_ms);
  const CellGrid& footprint = truth_.footprint();
  const std::vector<Eigen::Vector2d> footprint_W =
      mapping::footprint_in_world(config_.robot_footprint_B, T_world_base_);
  if (!map.empty() && !layer_costmap_) {
    CellSet freed;
    if (config_.footprint_clearing && !footprint_W.empty())
      for (const auto& [x, y] : mapping::footprint_cells(footprint_W, Eigen::Vector2d::Zero(), cell_m))
        freed.insert({x, y});
    snap.projection = guard_projection(columns, std::max(map.config().mark_threshold, 1), lethal, freed);
  }
  snap.self_marking =
      count_self_marking(lethal, footprint_W, cell_m, config_.self_ring_m, footprint, config_.tolerance_voxels);
  CostmapMatches m = match_costmap(lethal, footprint, observed_cells, config_.tolerance_voxels);
  snap.path_block = lethal_near_path(m.false_positive, config_.path_W, cell_m, config_.path_corridor_m);
  timer.emplace(times_.phantoms_ms);
  snap.lethal_cells = m.lethal;
  snap.costmap_precision = m.precision;
  snap.costmap_recall = m.recall;
  snap.phantoms = find_phantoms(lethal, footprint, cell_m, config_.phantom_clearance_m, config_.phantom_min_cells);
  snap.phantom_obstacles = static_cast<int>(snap.phantoms.size());
  top_down_.cell_m = cell_m;
  top_down_.true_positive = std::move(m.true_positive);
  top_down_.false_positive = std::move(m.false_positive);
  top_down_.false_negative = std::move(m.false_negative);
  if (top_down_version_ != truth_.version()) {  // the footprint's cells change with the truth only
    top_down_version_ = truth_.version();
    top_down_.truth = footprint.cells();
    top_down_.bounds_W = truth_.bounds_W();
  }
}

const EvaluationSnapshot& Evaluator::evaluate(double time_s, const sim::World& world, const mapping::VoxelMap& map) {
  update_truth(world);
  ++times_.evaluations;
  EvaluationSnapshot snap;
  snap.time_s = time_s;
  // The map's own projection and its voxels per column (for the projection guard) are computed beside the voxel
  // matching: both only read the map, and neither touches what the other writes (no truth, no mirror there).
  CellGrid lethal, columns;
  VoxelMatches mapped_matches, truth_matches;
  std::vector<CellKey> observed_cells;  // once per observed truth voxel
  tbb::parallel_invoke([&] { lethal = project_lethal(map, columns); },
                       [&] {
                         mapped_matches = match_mapped_voxels(map);
                         truth_matches = match_observed_truth(time_s, observed_cells);
                         const ScopedMsTimer timer(times_.observed_ms);
                         snap.cameras = camera_recalls(time_s, truth_matches);
                       });
  VoxelMatches matches = mapped_matches;
  matches.observed_truth = truth_matches.observed_truth;
  matches.matched_truth = truth_matches.matched_truth;
  const VoxelScores scores = voxel_scores(matches);
  snap.mapped_voxels = matches.mapped;
  snap.matched_mapped = matches.matched_mapped;
  snap.observed_truth_voxels = matches.observed_truth;
  snap.matched_truth = matches.matched_truth;
  snap.precision = scores.precision, snap.recall = scores.recall, snap.f1 = scores.f1, snap.iou = scores.iou;
  score_costmap(map, lethal, columns, CellGrid::of(observed_cells), snap);
  snapshots_.push_back(snap);
  return snapshots_.back();
}

EvaluationSummary Evaluator::finish(double time_s, const sim::World& world, const mapping::VoxelMap& map) {
  EvaluationSummary summary;
  summary.final = evaluate(time_s, world, map);
  summary.snapshots = snapshots_;
  summary.mean = mean_of(snapshots_, config_.recall_window_s);
  for (const auto& [name, result] : obstacles_) summary.obstacles.push_back(result);
  summary.accuracy = distance_stats_of_counts(mapped_.distance_counts());
  summary.clearing = clearing_.result(time_s);
  summary.observed_off_truth_voxels = off_truth_keys_.size();
  summary.false_clears = false_clears_;
  summary.occlusion = hidden_clears_.result();
  summary.voxels_3d = config_.layer_has_voxels;
  summary.costmap_projected = config_.costmap_projected;
  summary.truth = {truth_.geom_count(), truth_.mesh_geom_count(), truth_.mesh_triangle_count(), truth_.notes()};
  return summary;
}

}  // namespace stvl::evaluation

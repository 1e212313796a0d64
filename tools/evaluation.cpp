#include "tools/evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <tuple>

namespace stvl::tools {
namespace {

using stvl::CellKey;
using stvl::CellSet;
using stvl::VoxelKey;
using stvl::VoxelSet;

// Within tol (Chebyshev) of a member; the key itself first, the usual hit.
bool near_voxel(const VoxelSet& set, const VoxelKey& k, int tol) {
  if (set.count(k)) return true;
  for (int dx = -tol; dx <= tol; ++dx)
    for (int dy = -tol; dy <= tol; ++dy)
      for (int dz = -tol; dz <= tol; ++dz)
        if (set.count({k.x + dx, k.y + dy, k.z + dz})) return true;
  return false;
}

bool near_cell(const CellSet& set, const CellKey& c, int tol) {
  if (set.count(c)) return true;
  for (int dx = -tol; dx <= tol; ++dx)
    for (int dy = -tol; dy <= tol; ++dy)
      if (set.count({c.x + dx, c.y + dy})) return true;
  return false;
}

double ratio(std::size_t num, std::size_t den) { return den == 0 ? 0.0 : static_cast<double>(num) / den; }

bool is_mocap(const sim::World& world, int body_id) { return world.model()->body_mocapid[body_id] >= 0; }

sim::VoxelizeOptions voxelize_options(const Scenario& s) {
  sim::VoxelizeOptions options;
  options.voxel_size_m = s.map.voxel_size_m;
  options.bounds_W = Eigen::AlignedBox3d(Eigen::Vector3d(-1e6, -1e6, s.source.min_obstacle_height_m),
                                         Eigen::Vector3d(1e6, 1e6, s.source.max_obstacle_height_m));
  return options;
}

// The voxels [min_obstacle_height, max_obstacle_height] maps to in the z direction; truth voxels outside
// the map's marking band are dropped so they do not count as misses.
bool in_band(const VoxelKey& k, const Scenario& s) {
  const double zc = (k.z + 0.5) * s.map.voxel_size_m;
  return zc >= s.source.min_obstacle_height_m - 0.5 * s.map.voxel_size_m &&
         zc <= s.source.max_obstacle_height_m + 0.5 * s.map.voxel_size_m;
}

DistanceStats distance_stats(std::vector<double> d) {
  DistanceStats stats;
  stats.count = d.size();
  if (d.empty()) return stats;
  std::sort(d.begin(), d.end());
  const auto at = [&](double q) { return d[std::min(d.size() - 1, static_cast<std::size_t>(q * (d.size() - 1) + 0.5))]; };
  stats.mean_m = std::accumulate(d.begin(), d.end(), 0.0) / d.size();
  stats.median_m = at(0.5);
  stats.p90_m = at(0.9);
  stats.p99_m = at(0.99);
  stats.max_m = d.back();
  return stats;
}

}  // namespace

Evaluator::Evaluator(const sim::World& world, const Scenario& scenario)
    : scenario_(&scenario), voxel_m_(scenario.map.voxel_size_m) {
  refresh_truth(world);
}

void Evaluator::refresh_truth(const sim::World& world) {
  const auto& s = *scenario_;
  geoms_ = sim::obstacle_geoms(world);
  std::vector<sim::ObstacleGeom> statics;
  dynamic_geoms_.clear();
  for (const auto& g : geoms_) (is_mocap(world, g.body_id) ? dynamic_geoms_ : statics).push_back(g);
  const auto in_band_only = [&](std::vector<sim::BodyVoxels> bodies) {
    for (auto& body : bodies) {
      body.voxels.erase(std::remove_if(body.voxels.begin(), body.voxels.end(),
                                       [&](const VoxelKey& k) { return !in_band(k, s); }),
                        body.voxels.end());
      auto& result = obstacles_[body.body_name];
      result.name = body.body_name;
      result.truth_voxels = std::max(result.truth_voxels, body.voxels.size());
    }
    return bodies;
  };
  if (!statics_voxelized_) {
    statics_voxelized_ = true;
    static_bodies_ = in_band_only(sim::voxelize_bodies(statics, voxelize_options(s)));
    for (const auto& body : static_bodies_) static_truth_.insert(body.voxels.begin(), body.voxels.end());
    for (std::size_t b = 0; b < static_bodies_.size(); ++b)
      for (const auto& k : static_bodies_[b].voxels) static_body_of_.emplace(k, static_cast<int>(b));
    for (const auto& body : sim::footprints(statics, voxel_m_, s.source.min_obstacle_height_m, s.source.max_obstacle_height_m))
      static_footprint_.insert(body.cells.begin(), body.cells.end());
  }
  dynamic_bodies_ = in_band_only(sim::voxelize_bodies(dynamic_geoms_, voxelize_options(s)));
  dynamic_truth_.clear();
  for (const auto& body : dynamic_bodies_) {
    dynamic_truth_.insert(body.voxels.begin(), body.voxels.end());
    // A moving body's voxels become candidates for stale map voxels once it leaves them.
    for (const auto& k : body.voxels)
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) vacated_.insert({k.x + dx, k.y + dy, k.z + dz});
  }
}

bool Evaluator::is_truth(const VoxelKey& k) const { return static_truth_.count(k) || dynamic_truth_.count(k); }

bool Evaluator::near_truth(const VoxelKey& k) const {
  const int tol = scenario_->evaluation.tolerance_voxels;
  return near_voxel(static_truth_, k, tol) || near_voxel(dynamic_truth_, k, tol);
}

void Evaluator::observe(double time_s, const sensors::DepthImage& clean_depth,
                        const sensors::CameraIntrinsics& intrinsics, const Eigen::Isometry3d& T_world_camera) {
  const auto& s = *scenario_;
  const Eigen::Isometry3f T = T_world_camera.cast<float>();
  constexpr int kStride = 2;
  // Neighbouring pixels mostly fall in one voxel, and recording a voxel twice in a frame changes nothing:
  // skip the hash lookups when the key repeats.
  bool have_last = false;
  VoxelKey last{};
  for (int v = 0; v < clean_depth.height; v += kStride) {
    for (int u = 0; u < clean_depth.width; u += kStride) {
      const float z = clean_depth.at(u, v);
      if (!(z > 0.0f)) continue;
      const Eigen::Vector3f p_C = z * sensors::pixel_ray_C(intrinsics, u, v).cast<float>();
      if (p_C.norm() > s.source.obstacle_range_m) continue;
      const Eigen::Vector3d p_W = (T * p_C).cast<double>();
      if (p_W.z() < s.source.min_obstacle_height_m || p_W.z() > s.source.max_obstacle_height_m) continue;
      const VoxelKey key = stvl::voxel_key(p_W, voxel_m_);
      if (have_last && key == last) continue;
      have_last = true;
      last = key;
      last_seen_[key] = time_s;
      if (!is_truth(key)) off_truth_keys_.insert(key);
    }
  }
}

void Evaluator::observe_clearing(double time_s, const sim::World& world, const sensors::DepthImage& clean_depth,
                                 const sensors::CameraIntrinsics& intrinsics, const Eigen::Isometry3d& T_world_camera,
                                 const mapping::VoxelMap& map) {
  if (dynamic_geoms_.empty()) return;
  refresh_truth(world);
  // Stale voxels: in the map (as the previous update left it), where a moving body was, now far from every
  // true surface; seen through when the noise-free depth at their pixel lies beyond them.
  const Eigen::Isometry3d T_camera_world = T_world_camera.inverse();
  for (const VoxelKey& k : vacated_) {
    if (seen_through_.count(k) || near_truth(k)) continue;
    const Eigen::Vector3d c_W = stvl::voxel_center(k, voxel_m_);
    if (!map.lookup(c_W)) continue;
    const Eigen::Vector3d p_C = T_camera_world * c_W;
    const auto pixel = sensors::project_to_pixel(intrinsics, p_C);
    if (!pixel) continue;
    const int u = static_cast<int>(std::lround(pixel->x())), v = static_cast<int>(std::lround(pixel->y()));
    if (u < 0 || v < 0 || u >= clean_depth.width || v >= clean_depth.height) continue;
    const float depth = clean_depth.at(u, v);
    if (depth > 0.0f && depth > p_C.z() + voxel_m_) seen_through_[k] = time_s;
  }
}

void Evaluator::after_update(double time_s, const mapping::VoxelMap& map) {
  for (auto it = seen_through_.begin(); it != seen_through_.end();) {
    if (map.lookup(stvl::voxel_center(it->first, voxel_m_))) {
      ++it;
      continue;
    }
    latencies_s_.push_back(time_s - it->second);
    it = seen_through_.erase(it);
  }
}

const EvaluationSnapshot& Evaluator::evaluate(double time_s, const sim::World& world, const mapping::VoxelMap& map) {
  const auto& s = *scenario_;
  const int tol = s.evaluation.tolerance_voxels;
  refresh_truth(world);
  EvaluationSnapshot snap;
  snap.time_s = time_s;

  VoxelSet mapped;
  for (const auto& k : map.voxel_keys()) mapped.insert(k);
  snap.mapped_voxels = mapped.size();
  // Geoms bucketed by 1 m cells of their bounding boxes grown by kReach, so each distance tests a few geoms.
  constexpr double kCell = 1.0, kReach = 0.5;
  std::unordered_map<CellKey, std::vector<int>, stvl::CellKeyHash> geoms_near;
  std::vector<Eigen::AlignedBox3d> boxes;
  for (std::size_t g = 0; g < geoms_.size(); ++g) {
    boxes.push_back(geoms_[g].aabb_W());
    const auto lo = stvl::cell_key(boxes.back().min().head<2>().array() - kReach, kCell);
    const auto hi = stvl::cell_key(boxes.back().max().head<2>().array() + kReach, kCell);
    for (int x = lo.x; x <= hi.x; ++x)
      for (int y = lo.y; y <= hi.y; ++y) geoms_near[{x, y}].push_back(static_cast<int>(g));
  }
  for (const auto& k : mapped) {
    if (near_truth(k)) ++snap.matched_mapped;
    const Eigen::Vector3d c = stvl::voxel_center(k, voxel_m_);
    const auto bucket = geoms_near.find(stvl::cell_key(c.head<2>(), kCell));
    double best = std::numeric_limits<double>::infinity();
    const auto consider = [&](int g) {
      if (boxes[g].exteriorDistance(c) < best) best = std::min(best, std::abs(geoms_[g].signed_distance_m(c)));
    };
    if (bucket != geoms_near.end())
      for (int g : bucket->second) consider(g);
    if (!(best <= kReach))  // nothing within reach in this cell: fall back to every geom
      for (std::size_t g = 0; g < geoms_.size(); ++g) consider(static_cast<int>(g));
    if (std::isfinite(best)) distances_m_.push_back(best);
  }

  // Observed truth within the recall window, per body.
  std::vector<const sim::BodyVoxels*> bodies;
  for (const auto& body : static_bodies_) bodies.push_back(&body);
  for (const auto& body : dynamic_bodies_) bodies.push_back(&body);
  // The first body holding a voxel (static ones first); the static part is built once.
  std::unordered_map<VoxelKey, int, stvl::VoxelKeyHash> dynamic_body_of;
  for (std::size_t b = static_bodies_.size(); b < bodies.size(); ++b)
    for (const auto& k : bodies[b]->voxels) dynamic_body_of.emplace(k, static_cast<int>(b));
  const auto body_of = [&](const VoxelKey& k) {
    const auto s_it = static_body_of_.find(k);
    if (s_it != static_body_of_.end()) return s_it->second;
    const auto d_it = dynamic_body_of.find(k);
    return d_it != dynamic_body_of.end() ? d_it->second : -1;
  };
  std::vector<std::size_t> body_observed(bodies.size()), body_matched(bodies.size());
  CellSet observed_cells;
  for (auto it = last_seen_.begin(); it != last_seen_.end();) {
    if (it->second < time_s - s.evaluation.recall_window_s) {
      it = last_seen_.erase(it);
      continue;
    }
    const int body = body_of(it->first);
    if (body >= 0) {
      ++snap.observed_truth_voxels;
      ++body_observed[body];
      observed_cells.insert({it->first.x, it->first.y});
      if (near_voxel(mapped, it->first, tol)) ++snap.matched_truth, ++body_matched[body];
    }
    ++it;
  }
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    auto& result = obstacles_[bodies[b]->body_name];
    result.observed_voxels = std::max(result.observed_voxels, body_observed[b]);
    if (body_observed[b] >= static_cast<std::size_t>(s.evaluation.min_observed_voxels)) {
      result.observed = true;
      result.best_recall = std::max(result.best_recall, ratio(body_matched[b], body_observed[b]));
      result.detected = result.detected || result.best_recall >= 0.5;
    }
  }
  snap.precision = ratio(snap.matched_mapped, snap.mapped_voxels);
  snap.recall = ratio(snap.matched_truth, snap.observed_truth_voxels);
  snap.f1 = snap.precision + snap.recall > 0 ? 2 * snap.precision * snap.recall / (snap.precision + snap.recall) : 0;
  snap.iou = ratio(snap.matched_truth,
                   snap.observed_truth_voxels + (snap.mapped_voxels - snap.matched_mapped));

  // 2D: lethal cells against the true footprints in the band.
  CellSet footprint = static_footprint_;
  for (const auto& body :
       sim::footprints(dynamic_geoms_, voxel_m_, s.source.min_obstacle_height_m, s.source.max_obstacle_height_m))
    footprint.insert(body.cells.begin(), body.cells.end());
  mapping::CostmapOptions options;
  options.resolution_m = voxel_m_;
  options.min_obstacle_height_m = s.source.min_obstacle_height_m;
  options.max_obstacle_height_m = s.source.max_obstacle_height_m;
  CellSet lethal;
  if (!map.empty()) {
    const auto costmap = map.project_costmap(options);
    for (int iy = 0; iy < costmap.height; ++iy)
      for (int ix = 0; ix < costmap.width; ++ix)
        if (costmap.at(ix, iy) == mapping::kCostLethal)
          lethal.insert(stvl::cell_key({costmap.origin_m.x() + (ix + 0.5) * costmap.resolution_m,
                                       costmap.origin_m.y() + (iy + 0.5) * costmap.resolution_m},
                                      voxel_m_));
  }
  snap.lethal_cells = lethal.size();
  std::size_t lethal_true = 0, observed_hit = 0;
  top_down_ = {};
  top_down_.cell_m = voxel_m_;
  for (const auto& c : lethal) {
    const bool ok = near_cell(footprint, c, tol);
    lethal_true += ok;
    (ok ? top_down_.true_positive : top_down_.false_positive).push_back(c);
  }
  for (const auto& c : observed_cells) {
    if (near_cell(lethal, c, tol)) ++observed_hit;
    else top_down_.false_negative.push_back(c);
  }
  top_down_.truth.assign(footprint.begin(), footprint.end());
  snap.costmap_precision = ratio(lethal_true, lethal.size());
  snap.costmap_recall = ratio(observed_hit, observed_cells.size());

  // Phantoms: 8-connected lethal components with no true footprint within phantom_clearance_m.
  const int phantom_cells = static_cast<int>(std::ceil(s.evaluation.phantom_clearance_m / voxel_m_ - 1e-9));
  CellSet visited;
  for (const auto& start : lethal) {
    if (visited.count(start)) continue;
    std::vector<CellKey> stack{start};
    visited.insert(start);
    std::size_t size = 0;
    bool near_truth = false;
    Eigen::Vector2d sum_m = Eigen::Vector2d::Zero();
    while (!stack.empty()) {
      const CellKey c = stack.back();
      stack.pop_back();
      ++size;
      sum_m += Eigen::Vector2d(c.x + 0.5, c.y + 0.5) * voxel_m_;
      near_truth = near_truth || near_cell(footprint, c, phantom_cells);
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy) {
          const CellKey n{c.x + dx, c.y + dy};
          if (lethal.count(n) && visited.insert(n).second) stack.push_back(n);
        }
    }
    if (!near_truth && size >= static_cast<std::size_t>(s.evaluation.phantom_min_cells)) {
      ++snap.phantom_obstacles;
      snap.phantoms.push_back({sum_m.x() / double(size), sum_m.y() / double(size), size});
    }
  }
  std::sort(snap.phantoms.begin(), snap.phantoms.end(),
            [](const Phantom& a, const Phantom& b) { return std::tie(a.x_m, a.y_m) < std::tie(b.x_m, b.y_m); });

  Eigen::AlignedBox2d bounds;
  for (const auto& g : geoms_) {
    const auto box = g.aabb_W();
    bounds.extend(Eigen::Vector2d(box.min().x(), box.min().y()));
    bounds.extend(Eigen::Vector2d(box.max().x(), box.max().y()));
  }
  top_down_.bounds_W = bounds;
  snapshots_.push_back(snap);
  return snapshots_.back();
}

Eigen::Matrix3Xf Evaluator::truth_voxel_centers() const {
  std::vector<VoxelKey> keys(static_truth_.begin(), static_truth_.end());
  keys.insert(keys.end(), dynamic_truth_.begin(), dynamic_truth_.end());
  std::sort(keys.begin(), keys.end());
  Eigen::Matrix3Xf centers(3, static_cast<Eigen::Index>(keys.size()));
  for (std::size_t i = 0; i < keys.size(); ++i)
    centers.col(static_cast<Eigen::Index>(i)) = stvl::voxel_center(keys[i], voxel_m_).cast<float>();
  return centers;
}

EvaluationSummary Evaluator::finish(double time_s, const sim::World& world, const mapping::VoxelMap& map) {
  EvaluationSummary summary;
  summary.final = evaluate(time_s, world, map);
  summary.snapshots = snapshots_;
  const double warm_up_end = snapshots_.front().time_s + scenario_->evaluation.recall_window_s;
  std::size_t n = 0;
  EvaluationSnapshot& m = summary.mean;
  for (const auto& s : snapshots_) {
    if (s.time_s < warm_up_end && snapshots_.size() > 1) continue;
    ++n;
    m.precision += s.precision, m.recall += s.recall, m.f1 += s.f1, m.iou += s.iou;
    m.costmap_precision += s.costmap_precision, m.costmap_recall += s.costmap_recall;
    m.mapped_voxels += s.mapped_voxels, m.observed_truth_voxels += s.observed_truth_voxels;
    m.lethal_cells += s.lethal_cells;
    m.phantom_obstacles = std::max(m.phantom_obstacles, s.phantom_obstacles);
  }
  if (n > 0) {
    m.precision /= n, m.recall /= n, m.f1 /= n, m.iou /= n, m.costmap_precision /= n, m.costmap_recall /= n;
    m.mapped_voxels /= n, m.observed_truth_voxels /= n, m.lethal_cells /= n;
  }
  m.time_s = time_s;
  for (const auto& [name, result] : obstacles_) summary.obstacles.push_back(result);
  summary.accuracy = distance_stats(distances_m_);

  auto& c = summary.clearing;
  std::vector<double> latencies = latencies_s_;
  c.not_cleared = seen_through_.size();
  for (const auto& [key, first] : seen_through_) latencies.push_back(time_s - first);
  c.stale_voxels_seen_through = latencies.size();
  if (!latencies.empty()) {
    c.max_latency_s = *std::max_element(latencies.begin(), latencies.end());
    c.mean_latency_s = std::accumulate(latencies.begin(), latencies.end(), 0.0) / latencies.size();
  }
  summary.observed_off_truth_voxels = off_truth_keys_.size();
  return summary;
}

}  // namespace stvl::tools

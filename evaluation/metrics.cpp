#include "evaluation/metrics.hpp"

#include "common/units.hpp"
#include "mapping/footprint.hpp"

#include <unordered_map>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <tuple>

namespace stvl::evaluation {
namespace {

double ratio(std::size_t num, std::size_t den) { return den == 0 ? 0.0 : static_cast<double>(num) / den; }

}  // namespace

bool near_voxel(const VoxelSet& set, const VoxelKey& k, int tol) {
  return any_within(k, tol, [&](const VoxelKey& n) { return set.count(n) > 0; });
}

VoxelScores voxel_scores(const VoxelMatches& m) {
  VoxelScores s;
  s.precision = ratio(m.matched_mapped, m.mapped);
  s.recall = ratio(m.matched_truth, m.observed_truth);
  s.f1 = s.precision + s.recall > 0 ? 2 * s.precision * s.recall / (s.precision + s.recall) : 0;
  s.iou = ratio(m.matched_truth, m.observed_truth + (m.mapped - m.matched_mapped));
  return s;
}

void update_obstacle(ObstacleResult& o, std::size_t observed_voxels, std::size_t matched_voxels,
                     int min_observed_voxels) {
  o.observed_voxels = std::max(o.observed_voxels, observed_voxels);
  if (observed_voxels < static_cast<std::size_t>(min_observed_voxels)) return;
  o.observed = true;
  o.best_recall = std::max(o.best_recall, ratio(matched_voxels, observed_voxels));
  o.detected = o.detected || o.best_recall >= 0.5;
}

CostmapMatches match_costmap(const CellGrid& lethal, const CellGrid& footprint, const CellGrid& observed, int tol) {
  CostmapMatches m;
  m.lethal = lethal.size();
  m.observed = observed.size();
  lethal.for_each([&](const CellKey& c, int) {
    const bool ok = footprint.near(c, tol);
    m.lethal_true += ok;
    (ok ? m.true_positive : m.false_positive).push_back(c);
  });
  observed.for_each([&](const CellKey& c, int) {
    if (lethal.near(c, tol)) ++m.observed_hit;
    else m.false_negative.push_back(c);
  });
  m.precision = ratio(m.lethal_true, m.lethal);
  m.recall = ratio(m.observed_hit, m.observed);
  return m;
}

CellGrid lethal_cells(const mapping::Costmap2D& costmap, double cell_m) {
  const auto key_of = [&](int ix, int iy) {
    return cell_key({costmap.origin_m.x() + (ix + 0.5) * costmap.resolution_m,
                     costmap.origin_m.y() + (iy + 0.5) * costmap.resolution_m},
                    cell_m);
  };
  if (costmap.width <= 0 || costmap.height <= 0) return {};
  CellGrid lethal(key_of(0, 0), key_of(costmap.width - 1, costmap.height - 1));  // keys grow with ix, iy
  for (int iy = 0; iy < costmap.height; ++iy)
    for (int ix = 0; ix < costmap.width; ++ix)
      if (costmap.at(ix, iy) == mapping::kCostLethal) lethal.insert(key_of(ix, iy));
  return lethal;
}

PathBlock lethal_near_path(const std::vector<CellKey>& free_lethal, const std::vector<Eigen::Vector2d>& path_W,
                           double cell_m, double corridor_m) {
  PathBlock block;
  if (path_W.size() < 2) return block;
  block.first_along_m = std::numeric_limits<double>::infinity();
  for (const CellKey& c : free_lethal) {
    const Eigen::Vector2d p((c.x + 0.5) * cell_m, (c.y + 0.5) * cell_m);
    double best_m = std::numeric_limits<double>::infinity(), along_m = 0.0, start_m = 0.0;
    for (std::size_t i = 1; i < path_W.size(); ++i) {
      const Eigen::Vector2d a = path_W[i - 1], d = path_W[i] - a;
      const double length_m = d.norm();
      const double t = length_m > 0 ? std::clamp((p - a).dot(d) / (length_m * length_m), 0.0, 1.0) : 0.0;
      const double distance_m = (a + t * d - p).norm();
      if (distance_m < best_m) best_m = distance_m, along_m = start_m + t * length_m;
      start_m += length_m;
    }
    if (best_m > corridor_m) continue;
    ++block.cells;
    if (along_m < block.first_along_m) block.first_along_m = along_m, block.first_x_m = p.x(), block.first_y_m = p.y();
  }
  if (block.cells == 0) block.first_along_m = 0.0;
  return block;
}

CellGrid column_counts(const mapping::VoxelMap& map, double min_z_m, double max_z_m) {
  std::vector<CellKey> columns;  // once per leaf holding the column
  std::vector<int> voxels;
  map.for_each_column(min_z_m, max_z_m, [&](int x, int y, int n) { columns.push_back({x, y}), voxels.push_back(n); });
  CellGrid counts = CellGrid::covering(columns);
  for (std::size_t i = 0; i < columns.size(); ++i) counts.add(columns[i], voxels[i]);
  return counts;
}

ProjectionGuard guard_projection(const mapping::VoxelMap& map, const CellGrid& lethal, double min_z_m, double max_z_m,
                                 const CellSet& freed) {
  return guard_projection(column_counts(map, min_z_m, max_z_m), std::max(map.config().mark_threshold, 1), lethal,
                          freed);
}

ProjectionGuard guard_projection(const CellGrid& counts, int needed, const CellGrid& lethal, const CellSet& freed) {
  ProjectionGuard guard;
  lethal.for_each([&](const CellKey& cell, int) { guard.lethal_without_voxels += counts.count(cell) < needed; });
  counts.for_each([&](const CellKey& cell, int count) {
    guard.columns_without_lethal += count >= needed && !lethal.contains(cell) && !freed.count(cell);
  });
  return guard;
}

namespace {

double distance_to_segment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

}  // namespace

SelfMarking count_self_marking(const CellGrid& lethal, const std::vector<Eigen::Vector2d>& footprint_W, double cell_m,
                               double ring_m, const CellGrid& truth_footprint, int tol) {
  SelfMarking self;
  if (footprint_W.size() < 3) return self;
  CellSet inside;
  for (const auto& [x, y] : mapping::footprint_cells(footprint_W, Eigen::Vector2d::Zero(), cell_m))
    inside.insert({x, y});
  const auto is_self = [&](const CellKey& c) { return lethal.contains(c) && !truth_footprint.near(c, tol); };
  for (const auto& c : inside) self.inside += is_self(c);
  Eigen::AlignedBox2d box;
  for (const auto& p : footprint_W) box.extend(p);
  const int x0 = static_cast<int>(std::floor((box.min().x() - ring_m) / cell_m)),
            x1 = static_cast<int>(std::floor((box.max().x() + ring_m) / cell_m)),
            y0 = static_cast<int>(std::floor((box.min().y() - ring_m) / cell_m)),
            y1 = static_cast<int>(std::floor((box.max().y() + ring_m) / cell_m));
  for (int x = x0; x <= x1; ++x)
    for (int y = y0; y <= y1; ++y) {
      const CellKey c{x, y};
      if (inside.count(c) || !is_self(c)) continue;
      const Eigen::Vector2d centre_m((x + 0.5) * cell_m, (y + 0.5) * cell_m);
      double distance_m = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < footprint_W.size(); ++i)
        distance_m = std::min(distance_m,
                              distance_to_segment(centre_m, footprint_W[i], footprint_W[(i + 1) % footprint_W.size()]));
      if (distance_m <= ring_m + kLengthEpsilon_m) ++self.ring;
    }
  return self;
}

std::vector<Phantom> find_phantoms(const CellGrid& lethal, const CellGrid& footprint, double cell_m, double clearance_m,
                                   int min_cells) {
  const int clearance_cells = static_cast<int>(std::ceil(clearance_m / cell_m - kWholeCountEpsilon));
  std::vector<Phantom> phantoms;
  CellGrid visited(lethal.lo(), lethal.hi());
  std::vector<CellKey> stack;
  lethal.for_each([&](const CellKey& start, int) {
    if (visited.contains(start)) return;
    stack.assign(1, start);
    visited.insert(start);
    std::size_t size = 0;
    bool near_truth = false;
    std::int64_t sum_x = 0, sum_y = 0;  // exact, whatever the visiting order
    while (!stack.empty()) {
      const CellKey c = stack.back();
      stack.pop_back();
      ++size;
      sum_x += c.x, sum_y += c.y;
      near_truth = near_truth || footprint.near(c, clearance_cells);
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy) {
          const CellKey n{c.x + dx, c.y + dy};
          if (lethal.contains(n) && !visited.contains(n)) visited.insert(n), stack.push_back(n);
        }
    }
    const double n = static_cast<double>(size);
    if (!near_truth && size >= static_cast<std::size_t>(min_cells))
      phantoms.push_back({(static_cast<double>(sum_x) + 0.5 * n) * cell_m / n,
                          (static_cast<double>(sum_y) + 0.5 * n) * cell_m / n, size});
  });
  std::sort(phantoms.begin(), phantoms.end(),
            [](const Phantom& a, const Phantom& b) { return std::tie(a.x_m, a.y_m) < std::tie(b.x_m, b.y_m); });
  return phantoms;
}

LethalVsTruth lethal_against_truth(const mapping::Costmap2D& costmap, const CellGrid& footprint, double cell_m, int tol,
                                   double clearance_m, int min_cells) {
  LethalVsTruth out;
  std::vector<CellKey> covered;
  const double res = costmap.resolution_m;
  // The cells of cell_m whose centres (k + 0.5) cell_m lie in [lo, lo + res); the one holding the cell's centre
  // when none does (a costmap finer than cell_m).
  const auto span = [&](double lo) {
    std::int32_t first = static_cast<std::int32_t>(std::ceil(lo / cell_m - 0.5));
    std::int32_t last = static_cast<std::int32_t>(std::ceil((lo + res) / cell_m - 0.5)) - 1;
    if (last < first) first = last = static_cast<std::int32_t>(std::floor((lo + 0.5 * res) / cell_m));
    return std::make_pair(first, last);
  };
  for (int iy = 0; iy < costmap.height; ++iy)
    for (int ix = 0; ix < costmap.width; ++ix) {
      if (costmap.at(ix, iy) != mapping::kCostLethal) continue;
      ++out.lethal;
      const auto [x0, x1] = span(costmap.origin_m.x() + ix * res);
      const auto [y0, y1] = span(costmap.origin_m.y() + iy * res);
      bool near = false;
      for (std::int32_t kx = x0; kx <= x1; ++kx)
        for (std::int32_t ky = y0; ky <= y1; ++ky) {
          covered.push_back({kx, ky});
          near = near || footprint.near({kx, ky}, tol);
        }
      out.false_lethal += !near;
    }
  if (!covered.empty()) out.phantoms = find_phantoms(CellGrid::of(covered), footprint, cell_m, clearance_m, min_cells);
  return out;
}

DistanceStats distance_stats(std::vector<double> d) {
  DistanceStats stats;
  stats.count = d.size();
  if (d.empty()) return stats;
  std::sort(d.begin(), d.end());
  const auto at = [&](double q) {
    return d[std::min(d.size() - 1, static_cast<std::size_t>(q * (d.size() - 1) + 0.5))];
  };
  stats.mean_m = std::accumulate(d.begin(), d.end(), 0.0) / d.size();
  stats.median_m = at(0.5);
  stats.p90_m = at(0.9);
  stats.p99_m = at(0.99);
  stats.max_m = d.back();
  return stats;
}

DistanceStats distance_stats_of_counts(const std::map<double, std::size_t>& counts) {
  DistanceStats stats;
  for (const auto& [d, n] : counts) stats.count += n;
  if (stats.count == 0) return stats;
  const auto rank = [&](double q) {
    return std::min(stats.count - 1, static_cast<std::size_t>(q * (stats.count - 1) + 0.5));
  };
  const std::size_t median = rank(0.5), p90 = rank(0.9), p99 = rank(0.99);
  double sum = 0.0;
  std::size_t below = 0;  // values before the current one
  for (const auto& [d, n] : counts) {
    for (std::size_t i = 0; i < n; ++i) sum += d;
    const auto holds = [&](std::size_t r) { return r >= below && r < below + n; };
    if (holds(median)) stats.median_m = d;
    if (holds(p90)) stats.p90_m = d;
    if (holds(p99)) stats.p99_m = d;
    below += n;
  }
  stats.mean_m = sum / static_cast<double>(stats.count);
  stats.max_m = counts.rbegin()->first;
  return stats;
}

}  // namespace stvl::evaluation

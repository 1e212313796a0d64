#include "evaluation/truth.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <mutex>
#include <set>
#include <string>

#include "evaluation/metrics.hpp"

namespace stvl::evaluation {
namespace {

constexpr double kBucketCell_m = 1.0;
constexpr double kReach_m = 0.5;

bool is_mocap(const sim::World& world, int body_id) { return world.model()->body_mocapid[body_id] >= 0; }

// Truth voxels outside the map's marking band are dropped so that they do not count as misses.
bool in_band(const VoxelKey& k, const EvaluationConfig& c) {
  const double zc = (k.z + 0.5) * c.voxel_size_m;
  return zc >= c.min_obstacle_height_m - 0.5 * c.voxel_size_m && zc <= c.max_obstacle_height_m + 0.5 * c.voxel_size_m;
}

std::vector<truth::BodyVoxels> voxelize_in_band(const std::vector<truth::ObstacleGeom>& geoms,
                                                const EvaluationConfig& c) {
  truth::VoxelizeOptions options;
  options.voxel_size_m = c.voxel_size_m;
  options.bounds_W = Eigen::AlignedBox3d(Eigen::Vector3d(-1e6, -1e6, c.min_obstacle_height_m),
                                         Eigen::Vector3d(1e6, 1e6, c.max_obstacle_height_m));
  std::vector<truth::BodyVoxels> bodies = truth::voxelize_bodies(geoms, options);
  for (auto& body : bodies)
    body.voxels.erase(
        std::remove_if(body.voxels.begin(), body.voxels.end(), [&](const VoxelKey& k) { return !in_band(k, c); }),
        body.voxels.end());
  return bodies;
}

// Each note once per process, however many truths meet it.
void print_once(const std::string& note) {
  static std::mutex mutex;
  static std::set<std::string> printed;
  std::lock_guard<std::mutex> lock(mutex);
  if (printed.insert(note).second) std::fprintf(stderr, "stvl truth: %s\n", note.c_str());
}

// The same geom at the same pose (and so the same voxels, footprints and distances).
bool same_placement(const truth::ObstacleGeom& a, const truth::ObstacleGeom& b) {
  return a.geom_id == b.geom_id && a.T_world_geom.matrix() == b.T_world_geom.matrix() && a.size_m == b.size_m;
}
bool same_placement(const std::vector<truth::ObstacleGeom>& a, const std::vector<truth::ObstacleGeom>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!same_placement(a[i], b[i])) return false;
  return true;
}

// The moving bodies' voxels in the band, as voxelize_in_band(geoms) gives them, taking a body's voxels from
// `before` (made from before_geoms) when none of its geoms moved.
std::vector<truth::BodyVoxels> voxelize_moved_in_band(const std::vector<truth::ObstacleGeom>& geoms,
                                                      const std::vector<truth::ObstacleGeom>& before_geoms,
                                                      std::vector<truth::BodyVoxels>&& before,
                                                      const EvaluationConfig& c) {
  std::vector<truth::BodyVoxels> out;
  std::vector<std::vector<truth::ObstacleGeom>> of_body;  // geoms per body, in order of first appearance
  std::vector<bool> moved;
  for (std::size_t i = 0; i < geoms.size(); ++i) {
    std::size_t b = 0;
    while (b < out.size() && out[b].body_id != geoms[i].body_id) ++b;
    if (b == out.size())
      out.push_back({geoms[i].body_id, geoms[i].body_name, {}}), of_body.emplace_back(), moved.push_back(false);
    of_body[b].push_back(geoms[i]);
    moved[b] = moved[b] || geoms.size() != before_geoms.size() || !same_placement(geoms[i], before_geoms[i]);
  }
  for (std::size_t b = 0; b < out.size(); ++b) {
    if (!moved[b] && b < before.size() && before[b].body_id == out[b].body_id) {
      out[b].voxels = std::move(before[b].voxels);
      continue;
    }
    std::vector<truth::BodyVoxels> one = voxelize_in_band(of_body[b], c);
    if (!one.empty()) out[b].voxels = std::move(one.front().voxels);
  }
  return out;
}

// Appends to out every key within tol voxels (Chebyshev) of a key of voxels, each once: a dilation of the keys'
// bounding box in a dense grid, axis by axis (the keys of a body are few and close together). Boxes of more than
// kMaxCells fall back to a hash set.
void grow_keys(const std::vector<VoxelKey>& voxels, int tol, std::vector<VoxelKey>& out) {
  if (voxels.empty()) return;
  constexpr std::int64_t kMaxCells = std::int64_t{1} << 24;
  VoxelKey lo = voxels.front(), hi = voxels.front();
  for (const VoxelKey& k : voxels) {
    lo = {std::min(lo.x, k.x), std::min(lo.y, k.y), std::min(lo.z, k.z)};
    hi = {std::max(hi.x, k.x), std::max(hi.y, k.y), std::max(hi.z, k.z)};
  }
  const std::int64_t nx = std::int64_t(hi.x) - lo.x + 1 + 2 * tol, ny = std::int64_t(hi.y) - lo.y + 1 + 2 * tol,
                     nz = std::int64_t(hi.z) - lo.z + 1 + 2 * tol;
  if (nx * ny * nz > kMaxCells) {
    VoxelSet grown;
    for (const VoxelKey& k : voxels) any_within(k, tol, [&](const VoxelKey& n) { return grown.insert(n), false; });
    out.insert(out.end(), grown.begin(), grown.end());
    return;
  }
  const auto at = [&](std::int64_t x, std::int64_t y, std::int64_t z) { return (x * ny + y) * nz + z; };
  std::vector<std::uint8_t> a(std::size_t(nx * ny * nz), 0), b(a.size(), 0);
  for (const VoxelKey& k : voxels) a[std::size_t(at(k.x - lo.x + tol, k.y - lo.y + tol, k.z - lo.z + tol))] = 1;
  // One axis at a time: b = a dilated along the axis with stride `step` over `n` cells, then swapped back.
  const auto dilate = [&](std::int64_t n, std::int64_t step) {
    for (std::size_t i = 0; i < a.size(); ++i) {
      const std::int64_t pos = (std::int64_t(i) / step) % n;
      std::uint8_t v = 0;
      for (std::int64_t d = std::max<std::int64_t>(-tol, -pos); d <= tol && pos + d < n; ++d) v |= a[i + d * step];
      b[i] = v;
    }
    a.swap(b);
  };
  dilate(nz, 1);
  dilate(ny, nz);
  dilate(nx, ny * nz);
  for (std::int64_t x = 0; x < nx; ++x)
    for (std::int64_t y = 0; y < ny; ++y)
      for (std::int64_t z = 0; z < nz; ++z)
        if (a[std::size_t(at(x, y, z))])
          out.push_back({std::int32_t(lo.x - tol + x), std::int32_t(lo.y - tol + y), std::int32_t(lo.z - tol + z)});
}

}  // namespace

Truth::Truth(const sim::World& world, const EvaluationConfig& config) : config_(config) {
  config_.validate();
  notes_ = truth::truth_notes(world);
  for (const auto& n : notes_) print_once(n.note);
  geoms_ = truth::obstacle_geoms(world);
  poses_only_ = !truth::poses_decide_membership(world);
  std::vector<truth::ObstacleGeom> statics;
  for (const auto& g : geoms_) (is_mocap(world, g.body_id) ? dynamic_geoms_ : statics).push_back(g);
  static_bodies_ = voxelize_in_band(statics, config_);
  for (std::size_t b = 0; b < static_bodies_.size(); ++b)  // a key in several bodies keeps the first
    for (const auto& k : static_bodies_[b].voxels) static_truth_.insert(k, static_cast<int>(b));
  std::vector<CellKey> cells;
  for (const auto& body :
       truth::footprints(statics, config_.voxel_size_m, config_.min_obstacle_height_m, config_.max_obstacle_height_m))
    cells.insert(cells.end(), body.cells.begin(), body.cells.end());
  static_footprint_ = CellGrid::of(cells);
  update(world);
}

void Truth::update(const sim::World& world) {
  // Which geoms there are is fixed unless a plane rides a moving body: then the list is made again.
  std::vector<truth::ObstacleGeom> geoms, dynamic;
  if (poses_only_) {
    dynamic = dynamic_geoms_;
    truth::refresh_poses(world, dynamic);
  } else {
    geoms = truth::obstacle_geoms(world);
    for (const auto& g : geoms)
      if (is_mocap(world, g.body_id)) dynamic.push_back(g);
  }
  if (version_ > 0 && same_placement(dynamic, dynamic_geoms_)) return;
  ++version_;
  if (poses_only_) truth::refresh_poses(world, geoms_);
  else geoms_ = std::move(geoms);
  dynamic_bodies_ = voxelize_moved_in_band(dynamic, dynamic_geoms_, std::move(dynamic_bodies_), config_);
  dynamic_geoms_ = std::move(dynamic);
  dynamic_near_.for_each([&](const VoxelKey& k) { touched_.push_back(k); });  // near the bodies before
  dynamic_truth_.clear();
  dynamic_near_.clear();
  bodies_.clear();
  for (const auto& body : static_bodies_) bodies_.push_back(&body);
  std::vector<VoxelKey> grown;
  for (const auto& body : dynamic_bodies_) {
    const int index = static_cast<int>(bodies_.size());
    bodies_.push_back(&body);
    grown.clear();
    grow_keys(body.voxels, config_.tolerance_voxels, grown);
    for (const auto& k : grown) dynamic_near_.insert(k);
    for (const auto& k : body.voxels) {
      dynamic_truth_.insert(k, index);  // a key of several bodies keeps the first
      // A voxel once a body's has all its neighbours in vacated_ already; the others add theirs in this order
      // (vacated_'s iteration order is the order clearing records in).
      if (vacated_done_.contains(k)) continue;
      vacated_done_.insert(k);
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const VoxelKey n{k.x + dx, k.y + dy, k.z + dz};
            if (vacated_mask_.contains(n)) continue;
            vacated_mask_.insert(n);
            vacated_.insert(n);
            touched_.push_back(n);
          }
    }
  }
  dynamic_near_.for_each([&](const VoxelKey& k) { touched_.push_back(k); });  // and after
  index_geoms();
}

void Truth::index_geoms() {
  geoms_near_.clear();
  boxes_.clear();
  for (std::size_t g = 0; g < geoms_.size(); ++g) {
    boxes_.push_back(geoms_[g].aabb_W());
    const auto lo = cell_key(boxes_.back().min().head<2>().array() - kReach_m, kBucketCell_m);
    const auto hi = cell_key(boxes_.back().max().head<2>().array() + kReach_m, kBucketCell_m);
    const bool moving = std::any_of(dynamic_geoms_.begin(), dynamic_geoms_.end(),
                                    [&](const truth::ObstacleGeom& d) { return d.geom_id == geoms_[g].geom_id; });
    for (int x = lo.x; x <= hi.x; ++x)
      for (int y = lo.y; y <= hi.y; ++y) {
        Bucket& bucket = geoms_near_[{x, y}];
        bucket.geoms.push_back(static_cast<int>(g));
        bucket.has_moving = bucket.has_moving || moving;
      }
  }
}

bool Truth::contains(const VoxelKey& k) const { return static_truth_.contains(k) || dynamic_truth_.contains(k); }

bool Truth::near(const VoxelKey& k, int tol) const {
  return near_static_mask(k, tol) || any_within(k, tol, [&](const VoxelKey& n) { return dynamic_truth_.contains(n); });
}

bool Truth::near_static(const VoxelKey& k) const { return near_static_mask(k, config_.tolerance_voxels); }

bool Truth::near_static_mask(const VoxelKey& k, int tol) const {
  return any_within(k, tol, [&](const VoxelKey& n) { return static_truth_.contains(n); });
}

int Truth::body_of(const VoxelKey& k) const {
  const int body = static_body_of(k);
  return body >= 0 ? body : moving_body_of(k);
}

int Truth::static_body_of(const VoxelKey& k) const { return static_truth_.label_of(k); }

int Truth::moving_body_of(const VoxelKey& k) const { return dynamic_truth_.label_of(k); }

const CellGrid& Truth::footprint() const {
  if (footprint_version_ == version_) return footprint_;
  footprint_version_ = version_;
  std::vector<CellKey> moving;
  for (const auto& body : truth::footprints(dynamic_geoms_, config_.voxel_size_m, config_.min_obstacle_height_m,
                                            config_.max_obstacle_height_m))
    moving.insert(moving.end(), body.cells.begin(), body.cells.end());
  if (std::all_of(moving.begin(), moving.end(), [&](const CellKey& c) { return static_footprint_.covers(c); })) {
    footprint_ = static_footprint_;  // one copy of the static box
  } else {
    std::vector<CellKey> corners = moving;  // a box for the static cells and the moving ones
    if (!static_footprint_.empty())
      corners.push_back(static_footprint_.lo()), corners.push_back(static_footprint_.hi());
    footprint_ = CellGrid::covering(corners);
    static_footprint_.for_each([&](const CellKey& c, int) { footprint_.insert(c); });
  }
  for (const CellKey& c : moving) footprint_.insert(c);
  return footprint_;
}

std::optional<double> Truth::distance_in(const Bucket* bucket, const Eigen::Vector3d& c, bool* fell_back) const {
  double best = std::numeric_limits<double>::infinity();
  const auto consider = [&](int g) {
    if (boxes_[g].exteriorDistance(c) < best) best = std::min(best, std::abs(geoms_[g].signed_distance_m(c)));
  };
  if (bucket)
    for (int g : bucket->geoms) consider(g);
  *fell_back = !(best <= kReach_m);
  if (*fell_back)  // nothing within reach in this cell: fall back to every geom
    for (std::size_t g = 0; g < geoms_.size(); ++g) consider(static_cast<int>(g));
  if (!std::isfinite(best)) return std::nullopt;
  return best;
}

std::optional<double> Truth::distance_to_surface_m(const Eigen::Vector3d& c) const {
  const auto bucket = geoms_near_.find(cell_key(c.head<2>(), kBucketCell_m));
  bool fell_back = false;
  return distance_in(bucket == geoms_near_.end() ? nullptr : &bucket->second, c, &fell_back);
}

std::optional<double> Truth::voxel_distance_to_surface_m(const VoxelKey& key, bool* fixed) const {
  const Eigen::Vector3d c = voxel_center(key, config_.voxel_size_m);
  const auto bucket = geoms_near_.find(cell_key(c.head<2>(), kBucketCell_m));
  // Only static geoms decide the distance of a voxel whose bucket holds no moving geom, unless the search falls
  // back to every geom; those static geoms and their order never change.
  const bool static_bucket = bucket != geoms_near_.end() && !bucket->second.has_moving;
  bool fell_back = false;
  const auto d = distance_in(bucket == geoms_near_.end() ? nullptr : &bucket->second, c, &fell_back);
  if (fixed) *fixed = static_bucket && !fell_back && d;
  return d;
}

bool Truth::moving_distance_in(const VoxelKey& lo, const VoxelKey& hi) const {
  const CellKey a = cell_key(voxel_center(lo, config_.voxel_size_m).head<2>(), kBucketCell_m);
  const CellKey b = cell_key(voxel_center(hi, config_.voxel_size_m).head<2>(), kBucketCell_m);
  for (int x = a.x; x <= b.x; ++x)
    for (int y = a.y; y <= b.y; ++y)
      if (const auto bucket = geoms_near_.find({x, y}); bucket != geoms_near_.end() && bucket->second.has_moving)
        return true;
  return false;
}

std::size_t Truth::mesh_geom_count() const {
  return std::count_if(geoms_.begin(), geoms_.end(), [](const truth::ObstacleGeom& g) { return g.mesh != nullptr; });
}

std::size_t Truth::mesh_triangle_count() const {
  std::size_t n = 0;
  for (const auto& g : geoms_) n += g.mesh ? g.mesh->faces().size() : 0;
  return n;
}

Eigen::AlignedBox2d Truth::bounds_W() const {
  Eigen::AlignedBox2d bounds;
  for (const auto& g : geoms_) {
    const auto box = g.aabb_W();
    bounds.extend(Eigen::Vector2d(box.min().x(), box.min().y()));
    bounds.extend(Eigen::Vector2d(box.max().x(), box.max().y()));
  }
  return bounds;
}

Eigen::Matrix3Xf Truth::voxel_centers() const {
  std::vector<VoxelKey> keys;
  dynamic_truth_.for_each([&](const VoxelKey& k) { keys.push_back(k); });
  static_truth_.for_each([&](const VoxelKey& k) {
    if (!dynamic_truth_.contains(k)) keys.push_back(k);  // once, as in a set of both
  });
  std::sort(keys.begin(), keys.end());
  Eigen::Matrix3Xf centers(3, static_cast<Eigen::Index>(keys.size()));
  for (std::size_t i = 0; i < keys.size(); ++i)
    centers.col(static_cast<Eigen::Index>(i)) = voxel_center(keys[i], config_.voxel_size_m).cast<float>();
  return centers;
}

}  // namespace stvl::evaluation

// The only translation unit that includes OpenVDB.
#include "mapping/voxel_map.hpp"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Prune.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <utility>

#include "common/atomic_file.hpp"
#include "mapping/frustum.hpp"
#include "mapping/ray_walk.hpp"

namespace stvl::mapping {
namespace {

using GridT = openvdb::DoubleGrid;
using TreeT = GridT::TreeType;
using LeafT = TreeT::LeafNodeType;
using Internal2T = TreeT::RootNodeType::ChildNodeType;
using Internal1T = Internal2T::ChildNodeType;
using openvdb::Coord;

constexpr double kBackground = 0.0;
constexpr double kMaxIndex = 1 << 30;  // keys beyond this are not representable; such points are skipped
constexpr double kMinMarkDistanceSq = 1e-4;  // STVL skips points within 1 cm of the sensor
const char* const kGridName = "stvl_voxels";

Coord leaf_origin(const Coord& c) { return Coord(c.x() & ~7, c.y() & ~7, c.z() & ~7); }

struct CentreBox {
  double voxel_size;
  Eigen::AlignedBox3d operator()(const openvdb::CoordBBox& box) const {
    const Eigen::Vector3d lo(box.min().x() + 0.5, box.min().y() + 0.5, box.min().z() + 0.5);
    const Eigen::Vector3d hi(box.max().x() + 0.5, box.max().y() + 0.5, box.max().z() + 0.5);
    return Eigen::AlignedBox3d(lo * voxel_size, hi * voxel_size);
  }
};

struct Frustum {
  DepthCameraFrustum shape;
  double decay_acceleration_per_s3;
};

void ensure_openvdb_initialized() {
  static const bool initialized = [] {
    openvdb::initialize();
    return true;
  }();
  (void)initialized;
}

}  // namespace

struct VoxelMap::Impl {
  StvlConfig config;
  GridT::Ptr grid;
  double latest_time_s = -std::numeric_limits<double>::infinity();
  // Expiry index (bounded walk, linear decay): every leaf holds an entry due no later than its oldest
  // voxel's expiry; `due_by_leaf` mirrors `due_queue` so an entry can be moved earlier.
  std::set<std::pair<double, Coord>> due_queue;
  std::unordered_map<Coord, double> due_by_leaf;

  explicit Impl(const StvlConfig& c) : config(c) {
    ensure_openvdb_initialized();
    grid = GridT::create(kBackground);
    grid->setName(kGridName);
    auto transform = openvdb::math::Transform::createLinearTransform(config.voxel_size_m);
    transform->postTranslate(openvdb::Vec3d(config.voxel_size_m / 2));
    grid->setTransform(transform);
  }

  bool uses_expiry_index() const {
    return config.clearing_walk == ClearingWalk::kBounded && config.decay_model == DecayModel::kLinear;
  }

  void check_time(double time_s) {
    if (!std::isfinite(time_s)) throw std::invalid_argument("time_s = " + std::to_string(time_s) + " is not finite");
    if (time_s < latest_time_s)
      throw std::invalid_argument("time_s = " + std::to_string(time_s) + " is earlier than the map's latest time " +
                                  std::to_string(latest_time_s));
    latest_time_s = time_s;
  }

  bool to_key(const Eigen::Vector3d& p_W, Coord& key) const {
    const Eigen::Vector3d scaled = (p_W / config.voxel_size_m).array().floor();
    if (!(scaled.cwiseAbs().maxCoeff() < kMaxIndex)) return false;
    key = Coord(static_cast<int>(scaled.x()), static_cast<int>(scaled.y()), static_cast<int>(scaled.z()));
    return true;
  }

  Eigen::Vector3d centre(const Coord& c) const {
    return Eigen::Vector3d(c.x() + 0.5, c.y() + 0.5, c.z() + 0.5) * config.voxel_size_m;
  }

  double base_time_left(double age) const {
    switch (config.decay_model) {
      case DecayModel::kLinear: return config.voxel_decay_s - age;
      case DecayModel::kExponential: return config.voxel_decay_s * std::exp(-age);
      case DecayModel::kPersistent: return config.voxel_decay_s;
    }
    return config.voxel_decay_s;
  }

  void schedule(const Coord& leaf, double due) {
    auto [it, inserted] = due_by_leaf.try_emplace(leaf, due);
    if (!inserted) {
      if (due >= it->second) return;
      due_queue.erase({it->second, leaf});
      it->second = due;
    }
    due_queue.emplace(due, leaf);
  }

  void unschedule(const Coord& leaf) {
    auto it = due_by_leaf.find(leaf);
    if (it == due_by_leaf.end()) return;
    due_queue.erase({it->second, leaf});
    due_by_leaf.erase(it);
  }

  void rebuild_expiry_index() {
    due_queue.clear();
    due_by_leaf.clear();
    if (!uses_expiry_index()) return;
    for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf) {
      double oldest = std::numeric_limits<double>::infinity();
      for (auto v = leaf->cbeginValueOn(); v; ++v) oldest = std::min(oldest, *v);
      if (std::isfinite(oldest)) schedule(leaf->origin(), oldest + config.voxel_decay_s);
    }
  }

  // Replaces empty leaves by inactive tiles, and internal nodes left without children likewise.
  void delete_empty_leaves(std::vector<Coord>& leaf_origins) {
    std::sort(leaf_origins.begin(), leaf_origins.end());
    leaf_origins.erase(std::unique(leaf_origins.begin(), leaf_origins.end()), leaf_origins.end());
    TreeT& tree = grid->tree();
    std::vector<Coord> parents;
    for (const Coord& origin : leaf_origins) {
      const LeafT* leaf = tree.probeConstLeaf(origin);
      if (leaf == nullptr || !leaf->isEmpty()) continue;
      tree.addTile(1, origin, kBackground, false);
      if (uses_expiry_index()) unschedule(origin);
      parents.push_back(Coord(origin.x() & ~127, origin.y() & ~127, origin.z() & ~127));
    }
    std::sort(parents.begin(), parents.end());
    parents.erase(std::unique(parents.begin(), parents.end()), parents.end());
    for (const Coord& origin : parents) {
      const Internal1T* node = tree.probeConstNode<Internal1T>(origin);
      if (node != nullptr && node->getChildMask().isOff() && node->getValueMask().isOff())
        tree.addTile(2, origin, kBackground, false);
    }
    tree.clearAllAccessors();
  }

  // STVL's per-voxel rule. Returns true when the voxel is removed; otherwise may pull its value back.
  template <typename Iter>
  bool decay_voxel(Iter& it, const std::vector<Frustum>& frustums, double time_s, double* new_value) const {
    const double value = *it;
    const double age = time_s - value;
    const double base = base_time_left(age);
    *new_value = value;
    if (!frustums.empty()) {
      const Eigen::Vector3d c = centre(it.getCoord());
      for (const Frustum& f : frustums) {
        if (!f.shape.contains(c)) continue;
        const double acceleration = f.decay_acceleration_per_s3 * age * age * age / 6.0;
        if (base - acceleration < 0.0) {
          it.setValueOff();
          return true;
        }
        if (acceleration != 0.0) {
          *new_value = value - acceleration;
          it.setValue(*new_value);
        }
        return false;
      }
    }
    if (base < 0.0) {
      it.setValueOff();
      return true;
    }
    return false;
  }

  void full_walk(const std::vector<Frustum>& frustums, double time_s, ClearStats& stats) {
    double unused = 0.0;
    for (auto it = grid->beginValueOn(); it; ++it) {
      ++stats.voxels_visited;
      if (decay_voxel(it, frustums, time_s, &unused)) ++stats.voxels_removed;
    }
    openvdb::tools::pruneInactive(grid->tree());
    stats.leaves_visited = grid->tree().leafCount();
  }

  void frustum_pass(const std::vector<Frustum>& frustums, double time_s, ClearStats& stats) {
    if (frustums.empty()) return;
    const CentreBox box_of{config.voxel_size_m};
    auto meets_any = [&](const openvdb::CoordBBox& box) {
      const Eigen::AlignedBox3d box_W = box_of(box);
      for (const Frustum& f : frustums)
        if (f.shape.may_intersect(box_W)) return true;
      return false;
    };
    std::vector<LeafT*> leaves;
    for (auto n2 = grid->tree().root().beginChildOn(); n2; ++n2) {
      if (!meets_any(n2->getNodeBoundingBox())) continue;
      for (auto n1 = n2->beginChildOn(); n1; ++n1) {
        if (!meets_any(n1->getNodeBoundingBox())) continue;
        for (auto leaf = n1->beginChildOn(); leaf; ++leaf)
          if (meets_any(leaf->getNodeBoundingBox())) leaves.push_back(&*leaf);
      }
    }
    std::vector<Coord> emptied;
    const bool indexed = uses_expiry_index();
    for (LeafT* leaf : leaves) {
      ++stats.leaves_visited;
      double oldest = std::numeric_limits<double>::infinity();
      for (auto it = leaf->beginValueOn(); it; ++it) {
        ++stats.voxels_visited;
        double value = 0.0;
        if (decay_voxel(it, frustums, time_s, &value))
          ++stats.voxels_removed;
        else
          oldest = std::min(oldest, value);
      }
      if (leaf->isEmpty())
        emptied.push_back(leaf->origin());
      else if (indexed)
        schedule(leaf->origin(), oldest + config.voxel_decay_s);
    }
    delete_empty_leaves(emptied);
  }

  void expiry_pass(double time_s, ClearStats& stats) {
    if (!uses_expiry_index()) return;
    // Slack so that rounding in value + voxel_decay never hides a voxel the full walk would remove.
    const double due_limit = time_s + 1e-9 * (1.0 + std::abs(time_s) + config.voxel_decay_s);
    std::vector<Coord> due_leaves;
    auto it = due_queue.begin();
    for (; it != due_queue.end() && it->first <= due_limit; ++it) {
      if (due_leaves.size() == config.expiry_leaves_per_update) break;
      due_leaves.push_back(it->second);
    }
    for (; it != due_queue.end() && it->first < time_s; ++it) ++stats.expiry_backlog;
    std::vector<Coord> emptied;
    for (const Coord& origin : due_leaves) {
      unschedule(origin);
      LeafT* leaf = grid->tree().probeLeaf(origin);
      if (leaf == nullptr) continue;
      ++stats.leaves_visited;
      double oldest = std::numeric_limits<double>::infinity();
      for (auto v = leaf->beginValueOn(); v; ++v) {
        ++stats.voxels_visited;
        if (time_s - *v > config.voxel_decay_s) {
          v.setValueOff();
          ++stats.voxels_removed;
        } else {
          oldest = std::min(oldest, *v);
        }
      }
      if (leaf->isEmpty())
        emptied.push_back(origin);
      else
        schedule(origin, oldest + config.voxel_decay_s);
    }
    delete_empty_leaves(emptied);
  }

  // Dense table of leaf pointers over a cube of blocks, so the ray walk finds a block's leaf by indexing.
  struct LeafTable {
    Coord min_block;
    int n = 0;  // blocks per axis; 0 = not built (too large)
    double free_radius_vox = 0.0;  // no leaf lies nearer than this to the centre
    std::vector<LeafT*> leaves;
    bool covers(const Coord& block) const {
      const Coord r = block - min_block;
      return n > 0 && r.x() >= 0 && r.y() >= 0 && r.z() >= 0 && r.x() < 8 * n && r.y() < 8 * n && r.z() < 8 * n;
    }
    std::size_t index(const Coord& block) const {
      const Coord r = block - min_block;
      return (static_cast<std::size_t>(r.x() / 8) * n + r.y() / 8) * n + r.z() / 8;
    }
    LeafT* at(const Coord& block) const { return leaves[index(block)]; }
  };

  LeafTable leaf_table_around(const Eigen::Vector3d& centre, const Coord& centre_key, int radius_voxels) {
    constexpr std::size_t kMaxEntries = 1u << 21;
    LeafTable table;
    table.min_block = leaf_origin(centre_key - Coord(radius_voxels));
    const Coord max_block = leaf_origin(centre_key + Coord(radius_voxels));
    const int n = (max_block.x() - table.min_block.x()) / 8 + 1;
    if (static_cast<std::size_t>(n) * n * n > kMaxEntries) return table;
    table.n = n;
    table.leaves.assign(static_cast<std::size_t>(n) * n * n, nullptr);
    double free_sq = static_cast<double>(radius_voxels) * radius_voxels;
    const openvdb::CoordBBox region(table.min_block, max_block + Coord(7));
    for (auto n2 = grid->tree().root().beginChildOn(); n2; ++n2) {
      if (!region.hasOverlap(n2->getNodeBoundingBox())) continue;
      for (auto n1 = n2->beginChildOn(); n1; ++n1) {
        if (!region.hasOverlap(n1->getNodeBoundingBox())) continue;
        for (auto leaf = n1->beginChildOn(); leaf; ++leaf)
          if (table.covers(leaf->origin())) {
            table.leaves[table.index(leaf->origin())] = &*leaf;
            double distance_sq = 0.0;
            for (int a = 0; a < 3; ++a) {
              const double gap = std::max({leaf->origin()[a] - centre[a], centre[a] - (leaf->origin()[a] + 8), 0.0});
              distance_sq += gap * gap;
            }
            free_sq = std::min(free_sq, distance_sq);
          }
      }
    }
    table.free_radius_vox = std::sqrt(free_sq);
    return table;
  }

  // An active voxel a ray passed through: cleared once every ray of the frame has been walked.
  struct RayHit {
    const LeafT* leaf;
    openvdb::Index offset;
  };

  void raycast_pass(const std::vector<ClearingObservation>& observations, ClearStats& stats) {
    std::vector<Coord> touched;
    struct Walked {
      std::vector<RayHit> hits;
      std::size_t visited = 0;
    };
    tbb::enumerable_thread_specific<Walked> walked;
    for (const ClearingObservation& obs : observations) {
      const Eigen::Vector3d origin_W = obs.T_world_camera.translation();
      const Eigen::Vector3d s_vox = origin_W / config.voxel_size_m;  // as to_key divides: floor(s_vox) = start
      Coord start;
      if (!to_key(origin_W, start)) continue;
      const Eigen::Matrix3Xf& points = *obs.points_W;
      const double max_range_sq_m2 = obs.source.max_z_m * obs.source.max_z_m;
      const LeafTable table =
          leaf_table_around(s_vox, start, static_cast<int>(std::ceil(obs.source.max_z_m / config.voxel_size_m)) + 1);
      // Rays only read the tree (in parallel, one accessor per chunk); the voxels they pass are cleared after.
      tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, points.cols(), 1024),
                        [&](const tbb::blocked_range<Eigen::Index>& range) {
        Walked& mine = walked.local();
        auto accessor = grid->getConstAccessor();
        auto leaf_at = [&](const VoxelKey& block) -> const LeafT* {
          const Coord origin(block.x, block.y, block.z);
          return table.covers(origin) ? table.at(origin) : accessor.probeConstLeaf(origin);
        };
        auto collect = [&](const LeafT* leaf, const VoxelKey& key) {
          ++mine.visited;
          const openvdb::Index offset = ((key.x & 7) << 6) | ((key.y & 7) << 3) | (key.z & 7);
          if (leaf->isValueOn(offset)) mine.hits.push_back({leaf, offset});
        };
        for (Eigen::Index i = range.begin(); i != range.end(); ++i) {
          Eigen::Vector3d p_W = points.col(i).cast<double>();
          if (!p_W.allFinite()) continue;
          const double length_sq_m2 = (p_W - origin_W).squaredNorm();
          if (length_sq_m2 < 1e-18) continue;
          if (length_sq_m2 > max_range_sq_m2)
            p_W = origin_W + (p_W - origin_W) * (obs.source.max_z_m / std::sqrt(length_sq_m2));
          // The walk stops before the point's voxel floor(e_vox), the key mark() gives it.
          const Eigen::Vector3d e_vox = p_W / config.voxel_size_m;
          // Every block nearer than free_radius_vox is empty: skip that part of the ray (or all of it).
          const double length_vox = (e_vox - s_vox).norm();
          if (length_vox < table.free_radius_vox) continue;
          if (table.free_radius_vox > 1.0)
            walk_ray_blocks(s_vox + (e_vox - s_vox) * ((table.free_radius_vox - 0.5) / length_vox), e_vox, leaf_at,
                            collect);
          else
            walk_ray_blocks(s_vox, e_vox, leaf_at, collect);
        }
      });
      // Clearing is idempotent and counted once per voxel, so the result does not depend on the split.
      for (Walked& mine : walked) {
        for (const RayHit& hit : mine.hits) {
          LeafT* leaf = const_cast<LeafT*>(hit.leaf);  // the grid is ours and no ray is being walked now
          if (!leaf->isValueOn(hit.offset)) continue;
          leaf->setValueOff(hit.offset);
          ++stats.voxels_removed;
          touched.push_back(leaf->origin());
        }
        stats.voxels_visited += mine.visited;
        mine.hits.clear();
        mine.visited = 0;
      }
    }
    delete_empty_leaves(touched);
  }
};

VoxelMap::VoxelMap(const StvlConfig& config) {
  config.validate();
  impl_ = std::make_unique<Impl>(config);
}
VoxelMap::~VoxelMap() = default;
VoxelMap::VoxelMap(VoxelMap&&) noexcept = default;
VoxelMap& VoxelMap::operator=(VoxelMap&&) noexcept = default;

const StvlConfig& VoxelMap::config() const { return impl_->config; }
double VoxelMap::voxel_size_m() const { return impl_->config.voxel_size_m; }

std::size_t VoxelMap::mark(const Eigen::Matrix3Xf& points_W, const Eigen::Isometry3d& T_world_camera,
                           const ObservationSource& source, double time_s) {
  source.validate();
  validate_pose(T_world_camera);
  impl_->check_time(time_s);
  if (!source.marking) return 0;
  const Eigen::Vector3d origin_W = T_world_camera.translation();
  const double range_sq = source.obstacle_range_m * source.obstacle_range_m;
  const bool indexed = impl_->uses_expiry_index();
  const double due = time_s + impl_->config.voxel_decay_s;
  auto accessor = impl_->grid->getAccessor();
  Coord last_leaf(std::numeric_limits<int>::max());
  std::size_t marked = 0;
  for (Eigen::Index i = 0; i < points_W.cols(); ++i) {
    const Eigen::Vector3d p = points_W.col(i).cast<double>();
    if (!p.allFinite()) continue;
    const double distance_sq = (p - origin_W).squaredNorm();
    if (distance_sq > range_sq || distance_sq < kMinMarkDistanceSq) continue;
    if (p.z() < source.min_obstacle_height_m || p.z() > source.max_obstacle_height_m) continue;
    Coord key;
    if (!impl_->to_key(p, key)) continue;
    accessor.setValueOn(key, time_s);
    ++marked;
    if (indexed) {
      const Coord leaf = leaf_origin(key);
      if (leaf != last_leaf) {
        impl_->schedule(leaf, due);
        last_leaf = leaf;
      }
    }
  }
  return marked;
}

ClearStats VoxelMap::clear(const std::vector<ClearingObservation>& observations, double time_s) {
  std::vector<ClearingObservation> clearing;
  for (const ClearingObservation& obs : observations) {
    obs.source.validate();
    validate_pose(obs.T_world_camera);
    if (!obs.source.clearing) continue;
    if (impl_->config.clearing_mode == ClearingMode::kRaycast && obs.points_W == nullptr)
      throw std::invalid_argument("clearing_mode = raycast needs ClearingObservation::points_W, got null");
    clearing.push_back(obs);
  }
  impl_->check_time(time_s);
  ClearStats stats;
  std::vector<Frustum> frustums;
  if (impl_->config.clearing_mode == ClearingMode::kFrustum) {
    for (const ClearingObservation& obs : clearing)
      frustums.push_back({DepthCameraFrustum(obs.T_world_camera, obs.source), obs.source.decay_acceleration_per_s3});
  } else {
    impl_->raycast_pass(clearing, stats);
  }
  if (impl_->config.clearing_walk == ClearingWalk::kFullWalk) {
    impl_->full_walk(frustums, time_s, stats);
  } else {
    impl_->frustum_pass(frustums, time_s, stats);
    impl_->expiry_pass(time_s, stats);
  }
  return stats;
}

std::size_t VoxelMap::size() const { return impl_->grid->activeVoxelCount(); }
std::size_t VoxelMap::leaf_count() const { return impl_->grid->tree().leafCount(); }

VoxelKey VoxelMap::key_of(const Eigen::Vector3d& p_W) const {
  Coord key;
  if (!p_W.allFinite() || !impl_->to_key(p_W, key))
    throw std::invalid_argument("point (" + std::to_string(p_W.x()) + ", " + std::to_string(p_W.y()) + ", " +
                                std::to_string(p_W.z()) + ") has no voxel key");
  return {key.x(), key.y(), key.z()};
}

Eigen::Vector3d VoxelMap::center_of(const VoxelKey& key) const {
  return impl_->centre(Coord(key.x, key.y, key.z));
}

std::optional<double> VoxelMap::lookup(const Eigen::Vector3d& p_W) const {
  Coord key;
  if (!p_W.allFinite() || !impl_->to_key(p_W, key)) return std::nullopt;
  double value = 0.0;
  if (!impl_->grid->tree().probeValue(key, value)) return std::nullopt;
  return value;
}

std::vector<Voxel> VoxelMap::voxels() const {
  std::vector<Voxel> out;
  out.reserve(size());
  for (auto it = impl_->grid->cbeginValueOn(); it; ++it) {
    const Coord c = it.getCoord();
    out.push_back({{c.x(), c.y(), c.z()}, *it});
  }
  std::sort(out.begin(), out.end(), [](const Voxel& a, const Voxel& b) { return a.key < b.key; });
  return out;
}

std::vector<VoxelKey> VoxelMap::voxel_keys() const {
  std::vector<VoxelKey> keys;
  for (const Voxel& v : voxels()) keys.push_back(v.key);
  return keys;
}

Eigen::Matrix3Xf VoxelMap::voxel_centers() const {
  const auto keys = voxel_keys();
  Eigen::Matrix3Xf centres(3, static_cast<Eigen::Index>(keys.size()));
  for (std::size_t i = 0; i < keys.size(); ++i) centres.col(static_cast<Eigen::Index>(i)) = center_of(keys[i]).cast<float>();
  return centres;
}

void VoxelMap::set_voxels(const std::vector<Voxel>& voxels) {
  for (const Voxel& v : voxels)
    if (!std::isfinite(v.time_s)) throw std::invalid_argument("voxel time_s = " + std::to_string(v.time_s) + " is not finite");
  auto accessor = impl_->grid->getAccessor();
  const bool indexed = impl_->uses_expiry_index();
  for (const Voxel& v : voxels) {
    const Coord key(v.key.x, v.key.y, v.key.z);
    accessor.setValueOn(key, v.time_s);
    impl_->latest_time_s = std::max(impl_->latest_time_s, v.time_s);
    if (indexed) impl_->schedule(leaf_origin(key), v.time_s + impl_->config.voxel_decay_s);
  }
}

Costmap2D VoxelMap::project_costmap(const CostmapOptions& options) const {
  const double resolution = options.resolution_m == 0.0 ? impl_->config.voxel_size_m : options.resolution_m;
  if (!std::isfinite(resolution) || resolution <= 0.0)
    throw std::invalid_argument("costmap resolution = " + std::to_string(options.resolution_m) + " must be > 0");
  if (std::isnan(options.min_obstacle_height_m) || std::isnan(options.max_obstacle_height_m) ||
      options.min_obstacle_height_m > options.max_obstacle_height_m)
    throw std::invalid_argument("costmap min_obstacle_height = " + std::to_string(options.min_obstacle_height_m) +
                                " must be <= max_obstacle_height = " + std::to_string(options.max_obstacle_height_m));
  std::vector<Eigen::Vector2d> columns;
  for (auto it = impl_->grid->cbeginValueOn(); it; ++it) {
    const Eigen::Vector3d c = impl_->centre(it.getCoord());
    if (c.z() < options.min_obstacle_height_m || c.z() > options.max_obstacle_height_m) continue;
    columns.push_back(c.head<2>());
  }
  Costmap2D map;
  map.resolution_m = resolution;
  if (options.bounds_W) {
    const Eigen::AlignedBox2d& b = *options.bounds_W;
    if (!b.min().allFinite() || !b.max().allFinite() || (b.max() - b.min()).minCoeff() < 0.0)
      throw std::invalid_argument("costmap bounds_W must be finite with min <= max");
    map.origin_m.x() = b.min().x();
    map.origin_m.y() = b.min().y();
    const double w = std::max(1.0, std::ceil((b.max().x() - b.min().x()) / resolution - 1e-9));
    const double h = std::max(1.0, std::ceil((b.max().y() - b.min().y()) / resolution - 1e-9));
    if (!(w * h <= 1e8)) throw std::invalid_argument("costmap of " + std::to_string(w) + " x " + std::to_string(h) + " cells is too large");
    map.width = static_cast<int>(w);
    map.height = static_cast<int>(h);
  } else if (columns.empty()) {
    map.width = map.height = 1;
  } else {
    Eigen::AlignedBox2d extent;
    for (const auto& c : columns) extent.extend(c);
    const Eigen::Vector2d lo = (extent.min() / resolution).array().floor();
    const Eigen::Vector2d hi = (extent.max() / resolution).array().floor();
    const Eigen::Vector2d cells = (hi - lo).array() + 1.0;
    if (!(cells.prod() <= 1e8)) throw std::invalid_argument("costmap over the map's extent is too large; give bounds_W");
    map.origin_m.x() = lo.x() * resolution;
    map.origin_m.y() = lo.y() * resolution;
    map.width = static_cast<int>(hi.x() - lo.x()) + 1;
    map.height = static_cast<int>(hi.y() - lo.y()) + 1;
  }
  std::vector<int> counts(static_cast<std::size_t>(map.width) * map.height, 0);
  for (const auto& c : columns) {
    const double fx = std::floor((c.x() - map.origin_m.x()) / resolution);
    const double fy = std::floor((c.y() - map.origin_m.y()) / resolution);
    if (fx < 0 || fy < 0 || fx >= map.width || fy >= map.height) continue;
    ++counts[static_cast<std::size_t>(fy) * map.width + static_cast<std::size_t>(fx)];
  }
  const int threshold = std::max(impl_->config.mark_threshold, 1);
  map.cells.resize(counts.size());
  for (std::size_t i = 0; i < counts.size(); ++i) map.cells[i] = counts[i] >= threshold ? kCostLethal : kCostFree;
  return map;
}

void VoxelMap::save_vdb(const std::string& path) const {
  const StvlConfig& c = impl_->config;
  GridT::Ptr out = impl_->grid->copy();  // shares the tree; metadata is the copy's own
  out->setName(kGridName);
  out->insertMeta("voxel_size", openvdb::DoubleMetadata(c.voxel_size_m));
  out->insertMeta("voxel_decay", openvdb::DoubleMetadata(c.voxel_decay_s));
  out->insertMeta("decay_model", openvdb::StringMetadata(to_string(c.decay_model)));
  out->insertMeta("mark_threshold", openvdb::Int32Metadata(c.mark_threshold));
  out->insertMeta("clearing_mode", openvdb::StringMetadata(to_string(c.clearing_mode)));
  out->insertMeta("clearing_walk", openvdb::StringMetadata(to_string(c.clearing_walk)));
  out->insertMeta("expiry_leaves_per_update", openvdb::Int64Metadata(static_cast<openvdb::Int64>(c.expiry_leaves_per_update)));
  out->insertMeta("latest_time_s", openvdb::DoubleMetadata(impl_->latest_time_s));
  write_via_temporary(path, [&](const std::filesystem::path& temp) {
    try {
      openvdb::io::File file(temp.string());
      file.write(openvdb::GridCPtrVec{out});
      file.close();
    } catch (const openvdb::Exception& e) {
      throw std::runtime_error("cannot write '" + path + "': " + e.what());
    }
  });
}

VoxelMap VoxelMap::load_vdb(const std::string& path) {
  ensure_openvdb_initialized();
  GridT::Ptr grid;
  try {
    openvdb::io::File file(path);
    file.open();
    if (!file.hasGrid(kGridName)) throw std::runtime_error("'" + path + "' holds no grid named " + kGridName);
    grid = openvdb::gridPtrCast<GridT>(file.readGrid(kGridName));
    file.close();
  } catch (const openvdb::Exception& e) {
    throw std::runtime_error("cannot read '" + path + "': " + e.what());
  }
  if (!grid) throw std::runtime_error("'" + path + "': grid " + kGridName + " is not a DoubleGrid");
  StvlConfig config;
  try {
    auto meta_double = [&](const char* name, double fallback) {
      auto m = grid->getMetadata<openvdb::DoubleMetadata>(name);
      return m ? m->value() : fallback;
    };
    auto meta_string = [&](const char* name, const std::string& fallback) {
      auto m = grid->getMetadata<openvdb::StringMetadata>(name);
      return m ? m->value() : fallback;
    };
    if (!grid->getMetadata<openvdb::DoubleMetadata>("voxel_size")) throw std::invalid_argument("voxel_size metadata missing");
    config.voxel_size_m = meta_double("voxel_size", config.voxel_size_m);
    config.voxel_decay_s = meta_double("voxel_decay", config.voxel_decay_s);
    config.decay_model = parse_decay_model(meta_string("decay_model", to_string(config.decay_model)));
    if (auto m = grid->getMetadata<openvdb::Int32Metadata>("mark_threshold")) config.mark_threshold = m->value();
    config.clearing_mode = parse_clearing_mode(meta_string("clearing_mode", to_string(config.clearing_mode)));
    config.clearing_walk = parse_clearing_walk(meta_string("clearing_walk", to_string(config.clearing_walk)));
    if (auto m = grid->getMetadata<openvdb::Int64Metadata>("expiry_leaves_per_update"))
      config.expiry_leaves_per_update = static_cast<std::size_t>(std::max<openvdb::Int64>(m->value(), 0));
    config.validate();
    const double transform_size = grid->voxelSize().x();
    if (std::abs(transform_size - config.voxel_size_m) > 1e-9 * config.voxel_size_m)
      throw std::invalid_argument("transform voxel size " + std::to_string(transform_size) +
                                  " differs from voxel_size metadata " + std::to_string(config.voxel_size_m));
    VoxelMap map(config);
    map.impl_->latest_time_s = meta_double("latest_time_s", -std::numeric_limits<double>::infinity());
    for (auto it = grid->cbeginValueOn(); it; ++it)
      if (!std::isfinite(*it)) throw std::invalid_argument("voxel holds a non-finite time");
    map.impl_->grid = grid;
    map.impl_->grid->tree().clearAllAccessors();
    map.impl_->rebuild_expiry_index();
    return map;
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("'" + path + "' is not a valid stvl map: " + e.what());
  }
}

void VoxelMap::save_ply(const std::string& path) const {
  const std::vector<Voxel> all = voxels();
  std::string bytes = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(all.size()) +
                      "\nproperty float x\nproperty float y\nproperty float z\nproperty double time\nend_header\n";
  const std::uint16_t probe = 1;
  const bool little_endian = *reinterpret_cast<const std::uint8_t*>(&probe) == 1;
  auto append = [&](const void* data, std::size_t n) {
    const char* p = static_cast<const char*>(data);
    if (little_endian) {
      bytes.append(p, n);
    } else {
      for (std::size_t i = n; i-- > 0;) bytes.push_back(p[i]);
    }
  };
  for (const Voxel& v : all) {
    const Eigen::Vector3f c = center_of(v.key).cast<float>();
    for (int a = 0; a < 3; ++a) append(&c[a], sizeof(float));
    append(&v.time_s, sizeof(double));
  }
  write_file_atomically(path, bytes);
}

}  // namespace stvl::mapping

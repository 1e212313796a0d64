// Decay and expiry: STVL's per-voxel rule, the full walk, the frustum pass over the leaves that meet a frustum,
// and the per-leaf expiry index of the bounded walk.
#include <openvdb/tools/Prune.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "mapping/detail/voxel_map_impl.hpp"

namespace stvl::mapping {

using detail::Coord;
using detail::Frustum;
using detail::Internal1T;
using detail::kBackground;
using detail::LeafT;
using detail::TreeT;

namespace {

// A voxel removed, for clear()'s cleared_keys or removed_keys (either may be null).
void report(std::vector<VoxelKey>* cleared_keys, const Coord& c) {
  if (cleared_keys) cleared_keys->push_back({c.x(), c.y(), c.z()});
}

}  // namespace

void VoxelMap::Impl::schedule(const Coord& leaf, double due_s) {
  auto [it, inserted] = due_by_leaf.try_emplace(leaf, due_s);
  if (!inserted) {
    if (due_s >= it->second) return;
    due_queue.erase({it->second, leaf});
    it->second = due_s;
  }
  due_queue.emplace(due_s, leaf);
}

void VoxelMap::Impl::unschedule(const Coord& leaf) {
  auto it = due_by_leaf.find(leaf);
  if (it == due_by_leaf.end()) return;
  due_queue.erase({it->second, leaf});
  due_by_leaf.erase(it);
}

void VoxelMap::Impl::rebuild_expiry_index() {
  due_queue.clear();
  due_by_leaf.clear();
  if (!uses_expiry_index()) return;
  for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf) {
    double oldest_s = std::numeric_limits<double>::infinity();
    for (auto v = leaf->cbeginValueOn(); v; ++v) oldest_s = std::min(oldest_s, *v);
    if (std::isfinite(oldest_s)) schedule(leaf->origin(), oldest_s + config.voxel_decay_s);
  }
}

void VoxelMap::Impl::delete_empty_leaves(std::vector<Coord>& leaf_origins) {
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

// inline: called once per voxel by the walks below, as it was when it lived in the class body.
template <typename Iter>
inline bool VoxelMap::Impl::decay_voxel(Iter& it, const std::vector<Frustum>& frustums, double time_s,
                                        double* new_value_s, bool* by_frustum) const {
  const double value_s = *it;
  const double age_s = time_s - value_s;
  const double time_left_s = base_time_left_s(age_s);
  *new_value_s = value_s;
  *by_frustum = false;
  if (!frustums.empty()) {
    const Eigen::Vector3d centre = frustum_centre_W(it.getCoord());
    for (const Frustum& f : frustums) {
      if (!f.contains(centre)) continue;
      const double acceleration_s = 1. / 6. * f.decay_acceleration_per_s3 * (age_s * age_s * age_s);  // STVL's order
      if (time_left_s - acceleration_s < 0.0) {
        it.setValueOff();
        *by_frustum = time_left_s >= 0.0;  // plain decay would have kept it
        return true;
      }
      if (acceleration_s != 0.0) {
        *new_value_s = value_s - acceleration_s;
        it.setValue(*new_value_s);
      }
      return false;
    }
  }
  if (time_left_s < 0.0) {
    it.setValueOff();
    return true;
  }
  return false;
}

void VoxelMap::Impl::full_walk(const std::vector<Frustum>& frustums, double time_s, ClearStats& stats,
                               std::vector<VoxelKey>* cleared_keys, std::vector<VoxelKey>* removed_keys) {
  double unused = 0.0;
  bool by_frustum = false;
  for (auto it = grid->beginValueOn(); it; ++it) {
    ++stats.voxels_visited;
    if (!decay_voxel(it, frustums, time_s, &unused, &by_frustum)) continue;
    ++stats.voxels_removed;
    report(removed_keys, it.getCoord());
    if (by_frustum) report(cleared_keys, it.getCoord());
  }
  openvdb::tools::pruneInactive(grid->tree());
  stats.leaves_visited = grid->tree().leafCount();
}

void VoxelMap::Impl::frustum_pass(const std::vector<Frustum>& frustums, double time_s, ClearStats& stats,
                                  std::vector<VoxelKey>* cleared_keys, std::vector<VoxelKey>* removed_keys) {
  if (frustums.empty()) return;
  // World box spanned by the centres (as the frustum test takes them) of an index box's voxels.
  auto box_of = [this](const openvdb::CoordBBox& box) {
    return Eigen::AlignedBox3d(frustum_centre_W(box.min()), frustum_centre_W(box.max()));
  };
  auto meets_any = [&](const openvdb::CoordBBox& box) {
    const Eigen::AlignedBox3d box_W = box_of(box);
    for (const Frustum& f : frustums)
      if (f.may_intersect(box_W)) return true;
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
    double oldest_s = std::numeric_limits<double>::infinity();
    for (auto it = leaf->beginValueOn(); it; ++it) {
      ++stats.voxels_visited;
      double value_s = 0.0;
      bool by_frustum = false;
      if (decay_voxel(it, frustums, time_s, &value_s, &by_frustum)) {
        ++stats.voxels_removed;
        report(removed_keys, it.getCoord());
        if (by_frustum) report(cleared_keys, it.getCoord());
      } else {
        oldest_s = std::min(oldest_s, value_s);
      }
    }
    if (leaf->isEmpty()) emptied.push_back(leaf->origin());
    else if (indexed) schedule(leaf->origin(), oldest_s + config.voxel_decay_s);
  }
  delete_empty_leaves(emptied);
}

void VoxelMap::Impl::expiry_pass(double time_s, ClearStats& stats, std::vector<VoxelKey>* removed_keys) {
  if (!uses_expiry_index()) return;
  // Slack so that rounding in value + voxel_decay never hides a voxel the full walk would remove.
  const double due_limit_s = time_s + 1e-9 * (1.0 + std::abs(time_s) + config.voxel_decay_s);
  std::vector<Coord> due_leaves;
  auto it = due_queue.begin();
  for (; it != due_queue.end() && it->first <= due_limit_s; ++it) {
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
    double oldest_s = std::numeric_limits<double>::infinity();
    for (auto v = leaf->beginValueOn(); v; ++v) {
      ++stats.voxels_visited;
      if (time_s - *v > config.voxel_decay_s) {
        v.setValueOff();
        ++stats.voxels_removed;
        report(removed_keys, v.getCoord());
      } else {
        oldest_s = std::min(oldest_s, *v);
      }
    }
    if (leaf->isEmpty()) emptied.push_back(origin);
    else schedule(origin, oldest_s + config.voxel_decay_s);
  }
  delete_empty_leaves(emptied);
}

}  // namespace stvl::mapping

// Ray-cast clearing: every voxel between the optical centre and each point's voxel is removed at once. Rays are
// walked in parallel over a dense table of the leaves around the camera (mapping/ray_walk.hpp).
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "mapping/detail/voxel_map_impl.hpp"
#include "mapping/ray_walk.hpp"

namespace stvl::mapping {

using detail::Coord;
using detail::GridT;
using detail::leaf_origin;
using detail::LeafT;

namespace {

// Dense table of leaf pointers over a cube of blocks, so the ray walk finds a block's leaf by indexing.
struct LeafTable {
  Coord min_block;
  int n = 0;                     // blocks per axis; 0 = not built (too large)
  double free_radius_vox = 0.0;  // no leaf lies nearer than this to the centre
  std::vector<const LeafT*> leaves;
  bool covers(const Coord& block) const {
    const Coord r = block - min_block;
    return n > 0 && r.x() >= 0 && r.y() >= 0 && r.z() >= 0 && r.x() < 8 * n && r.y() < 8 * n && r.z() < 8 * n;
  }
  std::size_t index(const Coord& block) const {
    const Coord r = block - min_block;
    return (static_cast<std::size_t>(r.x() / 8) * n + r.y() / 8) * n + r.z() / 8;
  }
  const LeafT* at(const Coord& block) const { return leaves[index(block)]; }
};

LeafTable leaf_table_around(const GridT& grid, const Eigen::Vector3d& centre_vox, const Coord& centre_key,
                            int radius_vox) {
  constexpr std::size_t kMaxEntries = 1u << 21;
  LeafTable table;
  table.min_block = leaf_origin(centre_key - Coord(radius_vox));
  const Coord max_block = leaf_origin(centre_key + Coord(radius_vox));
  const int n = (max_block.x() - table.min_block.x()) / 8 + 1;
  if (static_cast<std::size_t>(n) * n * n > kMaxEntries) return table;
  table.n = n;
  table.leaves.assign(static_cast<std::size_t>(n) * n * n, nullptr);
  double free_sq_vox2 = static_cast<double>(radius_vox) * radius_vox;
  const openvdb::CoordBBox region(table.min_block, max_block + Coord(7));
  for (auto n2 = grid.tree().root().beginChildOn(); n2; ++n2) {
    if (!region.hasOverlap(n2->getNodeBoundingBox())) continue;
    for (auto n1 = n2->beginChildOn(); n1; ++n1) {
      if (!region.hasOverlap(n1->getNodeBoundingBox())) continue;
      for (auto leaf = n1->beginChildOn(); leaf; ++leaf)
        if (table.covers(leaf->origin())) {
          table.leaves[table.index(leaf->origin())] = &*leaf;
          double distance_sq_vox2 = 0.0;
          for (int a = 0; a < 3; ++a) {
            const double gap_vox =
                std::max({leaf->origin()[a] - centre_vox[a], centre_vox[a] - (leaf->origin()[a] + 8), 0.0});
            distance_sq_vox2 += gap_vox * gap_vox;
          }
          free_sq_vox2 = std::min(free_sq_vox2, distance_sq_vox2);
        }
    }
  }
  table.free_radius_vox = std::sqrt(free_sq_vox2);
  return table;
}

// An active voxel a ray passed through: cleared once every ray of the frame has been walked.
struct RayHit {
  const LeafT* leaf;
  openvdb::Index offset;
};

// What one thread's rays found: the active voxels they passed and how many voxels they visited.
struct Walked {
  std::vector<RayHit> hits;
  std::size_t visited = 0;
};

// The rays from the optical centre origin_W (s_vox in voxels) to each point of `points` (cut at max_z_m), walked
// in parallel; rays only read the tree (one accessor per chunk), each thread collecting the active voxels passed.
void walk_rays(const Eigen::Matrix3Xf& points, const GridT& grid, const LeafTable& table,
               const Eigen::Vector3d& origin_W, const Eigen::Vector3d& s_vox, double max_z_m, double voxel_size_m,
               tbb::enumerable_thread_specific<Walked>& walked) {
  const double max_range_sq_m2 = max_z_m * max_z_m;
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, points.cols(), 1024),
                    [&](const tbb::blocked_range<Eigen::Index>& range) {
                      Walked& mine = walked.local();
                      auto accessor = grid.getConstAccessor();
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
                          p_W = origin_W + (p_W - origin_W) * (max_z_m / std::sqrt(length_sq_m2));
                        // The walk stops before the point's voxel floor(e_vox), the key mark() gives it.
                        const Eigen::Vector3d e_vox = p_W / voxel_size_m;
                        // Every block nearer than free_radius_vox is empty: skip that part of the ray (or all of it).
                        const double length_vox = (e_vox - s_vox).norm();
                        if (length_vox < table.free_radius_vox) continue;
                        if (table.free_radius_vox > 1.0)
                          walk_ray_blocks(s_vox + (e_vox - s_vox) * ((table.free_radius_vox - 0.5) / length_vox), e_vox,
                                          leaf_at, collect);
                        else walk_ray_blocks(s_vox, e_vox, leaf_at, collect);
                      }
                    });
}

// Clears the voxels the rays passed, counted once per voxel (clearing is idempotent, so the result does not depend
// on the split), their keys into cleared_keys when given and their leaves into touched; empties `walked`.
void clear_hits(tbb::enumerable_thread_specific<Walked>& walked, ClearStats& stats, std::vector<VoxelKey>* cleared_keys,
                std::vector<Coord>& touched) {
  for (Walked& mine : walked) {
    for (const RayHit& hit : mine.hits) {
      LeafT* leaf = const_cast<LeafT*>(hit.leaf);  // the grid is this map's and no ray is being walked now
      if (!leaf->isValueOn(hit.offset)) continue;
      leaf->setValueOff(hit.offset);
      ++stats.voxels_removed;
      if (cleared_keys) {
        const Coord key = leaf->offsetToGlobalCoord(hit.offset);
        cleared_keys->push_back({key.x(), key.y(), key.z()});
      }
      touched.push_back(leaf->origin());
    }
    stats.voxels_visited += mine.visited;
    mine.hits.clear();
    mine.visited = 0;
  }
}

}  // namespace

void VoxelMap::Impl::raycast_pass(const std::vector<ClearingObservation>& observations, ClearStats& stats,
                                  std::vector<VoxelKey>* cleared_keys) {
  std::vector<Coord> touched;
  tbb::enumerable_thread_specific<Walked> walked;
  for (const ClearingObservation& obs : observations) {
    const Eigen::Vector3d origin_W = obs.T_world_camera.translation();
    const Eigen::Vector3d s_vox = origin_W / config.voxel_size_m;  // as to_key divides: floor(s_vox) = start
    Coord start;
    if (!to_key(origin_W, start)) continue;
    const int radius_vox = static_cast<int>(std::ceil(obs.source.max_z_m / config.voxel_size_m)) + 1;
    const LeafTable table = leaf_table_around(*grid, s_vox, start, radius_vox);
    walk_rays(*obs.points_W, *grid, table, origin_W, s_vox, obs.source.max_z_m, config.voxel_size_m, walked);
    if (obs.source.clear_on_no_return && obs.no_return_W)
      walk_rays(*obs.no_return_W, *grid, table, origin_W, s_vox, obs.source.max_z_m, config.voxel_size_m, walked);
    clear_hits(walked, stats, cleared_keys, touched);
  }
  delete_empty_leaves(touched);
}

}  // namespace stvl::mapping

#include "evaluation/reference/mapped_index.hpp"

namespace stvl::evaluation::reference {

VoxelMatches match_mapped(const mapping::VoxelMap& map, Truth& truth, int tol,
                          std::map<double, std::size_t>& distance_counts_m) {
  VoxelMatches m;
  map.for_each_key([&](const VoxelKey& k) {
    ++m.mapped;
    if (truth.near(k, tol)) ++m.matched_mapped;
    if (const auto d = truth.voxel_distance_to_surface_m(k)) ++distance_counts_m[*d];
  });
  return m;
}

}  // namespace stvl::evaluation::reference

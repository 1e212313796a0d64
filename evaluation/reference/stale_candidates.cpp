#include "evaluation/reference/stale_candidates.hpp"

namespace stvl::evaluation::reference {

VoxelSet stale_candidates(const Truth& truth) {
  VoxelSet out;
  for (const VoxelKey& k : truth.vacated())
    if (!truth.near_static(k) && !truth.near_moving(k)) out.insert(k);
  return out;
}

}  // namespace stvl::evaluation::reference

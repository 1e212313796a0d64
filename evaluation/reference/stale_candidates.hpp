#pragma once
// The places a stale map voxel can be, rebuilt from scratch (evaluation/stale_candidates.hpp keeps them
// incrementally): every voxel a moving body has occupied that is near neither a static nor a moving body now.
#include "common/voxel_key.hpp"
#include "evaluation/truth.hpp"

namespace stvl::evaluation::reference {

// Every vacated voxel of truth near neither a static nor a moving body, at the truth's tolerance.
VoxelSet stale_candidates(const Truth& truth);

}  // namespace stvl::evaluation::reference

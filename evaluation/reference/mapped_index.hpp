#pragma once
// The definition MappedIndex (evaluation/mapped_index.hpp) is checked against: one pass over the map's voxels,
// nothing remembered between calls. tests/evaluation compares the two; linked by tests only.
#include <cstddef>
#include <map>

#include "evaluation/metrics.hpp"
#include "evaluation/truth.hpp"
#include "mapping/voxel_map.hpp"

namespace stvl::evaluation::reference {

// Every mapped voxel counted, matched when truth.near(k, tol); its surface distance (m), when there is one,
// counted once in distance_counts_m (distance -> count, added to what it holds).
VoxelMatches match_mapped(const mapping::VoxelMap& map, Truth& truth, int tol,
                          std::map<double, std::size_t>& distance_counts_m);

}  // namespace stvl::evaluation::reference

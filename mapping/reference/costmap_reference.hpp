#pragma once
// Plain twin of VoxelMap::project_costmap (mapping/voxel_map.hpp), which counts a leaf's columns at once: the
// definition one voxel at a time, for tests only (library stvl_mapping_reference, linked by no module).
#include <cstddef>
#include <vector>

#include "mapping/costmap.hpp"
#include "mapping/voxel_map.hpp"

namespace stvl::mapping::reference {

// Per cell of `layout` (its origin_m, resolution_m, width, height; row-major, y rows), the number of the map's
// voxels whose centre lies in [options.min_obstacle_height_m, options.max_obstacle_height_m] (inclusive) and
// inside the cell. A cell is lethal in project_costmap when its count is >= max(mark_threshold, 1).
// `outside`, when not null, receives the number of voxels in the band that no cell holds.
std::vector<int> costmap_column_counts(const VoxelMap& map, const CostmapOptions& options, const Costmap2D& layout,
                                       std::size_t* outside = nullptr);

}  // namespace stvl::mapping::reference

#pragma once
// Plain twin of truth/mesh_voxelize.hpp, for tests only (library stvl_truth_reference, linked by no module): every
// voxel (cell) of the region against every triangle, with other predicates than the optimized code's. A triangle
// meets a box when clipping it to the box's six planes leaves something (Sutherland-Hodgman, not separating
// axes); a point is inside a closed mesh when a ray from it in a fixed oblique direction crosses an odd number of
// triangles (Möller-Trumbore, not vertical lines). Same contract as truth/mesh_voxelize.hpp.
#include <vector>

#include <Eigen/Geometry>

#include "common/voxel_key.hpp"
#include "truth/mesh_voxelize.hpp"

namespace stvl::truth::reference {

bool triangle_meets_box(const detail::Triangle& t, const Eigen::AlignedBox3d& box);
bool inside(const std::vector<detail::Triangle>& triangles, const Eigen::Vector3d& p);

std::vector<VoxelKey> voxelize_triangles(const std::vector<detail::Triangle>& triangles_W, bool closed,
                                         double voxel_size_m, bool solid, const Eigen::AlignedBox3d& region_W);
std::vector<CellKey> footprint_triangles(const std::vector<detail::Triangle>& triangles_W, bool closed,
                                         double cell_size_m, double min_z_m, double max_z_m);

}  // namespace stvl::truth::reference

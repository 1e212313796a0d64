#pragma once
// Exact voxels and footprint cells of triangles in the world frame (a mesh or height-field geom), for
// truth/ground_truth.cpp; truth/reference/mesh_voxelize_reference.hpp is the plain twin the tests compare with.
//  - surface: voxels whose closed cube (padded by 1e-9 m) meets a triangle (triangle_meets_box). Candidates per
//    triangle: the columns of its bounding box, and in each only the heights the triangle spans inside the column.
//  - solid (closed meshes): the surface voxels and those whose centre is inside: odd number of crossings above the
//    centre on a vertical line, the line moved by kColumnOffset * voxel size in x and y from the centre (generic,
//    so it passes through no vertex; a centre nearer the surface than that is in a surface voxel anyway).
//    Crossings are gathered per triangle over the columns its projection covers. Open meshes: the surface.
//  - footprint: cells whose column [min_z, max_z] meets a triangle, and (closed meshes) those whose column is
//    inside, tested at the band's middle height.
#include <array>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "common/voxel_key.hpp"

namespace stvl::truth::detail {

using Triangle = std::array<Eigen::Vector3d, 3>;

inline constexpr double kColumnOffset = 1.37035999e-4;  // of the voxel size, in x; y uses 1.6180339e-4
inline constexpr double kColumnOffsetY = 1.6180339e-4;
inline constexpr double kMaxCandidates = 2147483648.0;  // 2^31, as for the other shapes

// Voxels of edge voxel_size_m meeting `region_W`. Throws std::invalid_argument naming `what` when the triangles'
// bounding boxes hold more than kMaxCandidates voxels (or, solid, the region does), before allocating them.
// Sorted, unique.
std::vector<VoxelKey> voxelize_triangles(const std::vector<Triangle>& triangles_W, bool closed, double voxel_size_m,
                                         bool solid, const Eigen::AlignedBox3d& region_W, const std::string& what);

// Footprint cells (cell = floor(p / cell_size_m)) of the solid in the band [min_z_m, max_z_m]. Sorted, unique.
std::vector<CellKey> footprint_triangles(const std::vector<Triangle>& triangles_W, bool closed, double cell_size_m,
                                         double min_z_m, double max_z_m, const std::string& what);

}  // namespace stvl::truth::detail

#pragma once
// Triangles of MuJoCo's mesh, height field and finite plane geoms, in the geom's frame, for the ground truth
// (truth/ground_truth.hpp). obstacle_geoms() runs at every truth update: a mesh is built once per distinct content
// (a hash of the data its triangles come from) and kept while some geom holds it. Thread-safe.
#include <memory>
#include <string>

#include <mujoco/mujoco.h>

#include "truth/triangle_mesh.hpp"

namespace stvl::truth {

// Mesh asset `id` of the model as it is stored (label names it in errors).
std::shared_ptr<const TriangleMesh> model_mesh(const mjModel* m, int id, const std::string& label);
// Height field asset `id` as the renderer draws it (mjr_uploadHField): the grid, each cell split along its
// (c, r) -> (c+1, r+1) diagonal, the four sides down to the base at -size[3], and the base: closed. Throws
// std::invalid_argument for fewer than 2 x 2 samples.
std::shared_ptr<const TriangleMesh> height_field_mesh(const mjModel* m, int id, const std::string& label);
// A finite plane's rectangle of half sizes hx, hy (metres) at z = 0: two triangles.
std::shared_ptr<const TriangleMesh> rectangle_mesh(double hx, double hy, const std::string& label);

}  // namespace stvl::truth

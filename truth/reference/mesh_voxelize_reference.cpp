#include "truth/reference/mesh_voxelize_reference.hpp"

#include <cmath>

namespace stvl::truth::reference {
namespace {

constexpr double kPad_m = 1e-9;  // the cubes are closed and padded as in the optimized code

int index_of(double v, double s) { return static_cast<int>(std::floor(v / s)); }

}  // namespace

bool triangle_meets_box(const detail::Triangle& t, const Eigen::AlignedBox3d& box) {
  std::vector<Eigen::Vector3d> poly(t.begin(), t.end());
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const double bound = side == 0 ? box.min()[axis] : box.max()[axis];
      const double sign = side == 0 ? 1.0 : -1.0;  // keep sign * (p - bound) >= 0
      std::vector<Eigen::Vector3d> kept;
      for (std::size_t i = 0; i < poly.size(); ++i) {
        const Eigen::Vector3d& a = poly[i];
        const Eigen::Vector3d& b = poly[(i + 1) % poly.size()];
        const double da = sign * (a[axis] - bound), db = sign * (b[axis] - bound);
        if (da >= 0) kept.push_back(a);
        if ((da >= 0) != (db >= 0)) {
          Eigen::Vector3d p = a + (b - a) * (da / (da - db));
          p[axis] = bound;  // on the plane, whatever the rounding
          kept.push_back(p);
        }
      }
      poly = kept;
      if (poly.empty()) return false;
    }
  return true;
}

bool inside(const std::vector<detail::Triangle>& triangles, const Eigen::Vector3d& p) {
  const Eigen::Vector3d d = Eigen::Vector3d(0.5370, -0.3120, 0.7836).normalized();  // oblique, fixed
  bool odd = false;
  for (const auto& t : triangles) {
    const Eigen::Vector3d e1 = t[1] - t[0], e2 = t[2] - t[0];
    const Eigen::Vector3d h = d.cross(e2);
    const double det = e1.dot(h);
    if (det == 0) continue;  // parallel
    const Eigen::Vector3d s = p - t[0];
    const double u = s.dot(h) / det;
    if (u < 0 || u > 1) continue;
    const Eigen::Vector3d q = s.cross(e1);
    const double v = d.dot(q) / det;
    if (v < 0 || u + v > 1) continue;
    if (e2.dot(q) / det > 0) odd = !odd;
  }
  return odd;
}

std::vector<VoxelKey> voxelize_triangles(const std::vector<detail::Triangle>& triangles_W, bool closed, double s,
                                         bool solid, const Eigen::AlignedBox3d& region_W) {
  std::vector<VoxelKey> out;
  if (region_W.isEmpty()) return out;
  Eigen::Vector3i lo, hi;
  for (int i = 0; i < 3; ++i)
    lo[i] = index_of(region_W.min()[i] - kPad_m, s), hi[i] = index_of(region_W.max()[i] + kPad_m, s);
  for (int x = lo.x(); x <= hi.x(); ++x)
    for (int y = lo.y(); y <= hi.y(); ++y)
      for (int z = lo.z(); z <= hi.z(); ++z) {
        const Eigen::Vector3d corner(x * s, y * s, z * s);
        const Eigen::AlignedBox3d cube(corner.array() - kPad_m, corner.array() + s + kPad_m);
        bool hit = false;
        for (const auto& t : triangles_W) hit = hit || triangle_meets_box(t, cube);
        if (!hit && solid && closed) hit = inside(triangles_W, corner + Eigen::Vector3d::Constant(0.5 * s));
        if (hit) out.push_back({x, y, z});
      }
  return out;
}

std::vector<CellKey> footprint_triangles(const std::vector<detail::Triangle>& triangles_W, bool closed, double s,
                                         double min_z_m, double max_z_m) {
  std::vector<CellKey> out;
  Eigen::AlignedBox3d all;
  for (const auto& t : triangles_W) all.extend(t[0]).extend(t[1]).extend(t[2]);
  if (all.isEmpty()) return out;
  const int x0 = index_of(all.min().x() - kPad_m, s), x1 = index_of(all.max().x() + kPad_m, s);
  const int y0 = index_of(all.min().y() - kPad_m, s), y1 = index_of(all.max().y() + kPad_m, s);
  for (int x = x0; x <= x1; ++x)
    for (int y = y0; y <= y1; ++y) {
      const Eigen::AlignedBox3d column(Eigen::Vector3d(x * s - kPad_m, y * s - kPad_m, min_z_m - kPad_m),
                                       Eigen::Vector3d((x + 1) * s + kPad_m, (y + 1) * s + kPad_m, max_z_m + kPad_m));
      bool hit = false;
      for (const auto& t : triangles_W) hit = hit || triangle_meets_box(t, column);
      if (!hit && closed)
        hit = inside(triangles_W, Eigen::Vector3d((x + 0.5) * s, (y + 0.5) * s, 0.5 * (min_z_m + max_z_m)));
      if (hit) out.push_back({x, y});
    }
  return out;
}

}  // namespace stvl::truth::reference

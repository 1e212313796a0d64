#include "config/ros_lint_geometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace stvl::config::lint_geometry {
namespace {

using Vec = std::array<double, 3>;

double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec scaled(const Vec& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
Vec minus(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec unit(const Vec& a) { return scaled(a, 1.0 / std::sqrt(dot(a, a))); }

// World up in the optical frame (x right, y down, z forward) of a camera turned by `c`.
Vec up_in_optical(const CameraHeight& c) {
  // In camera_link: Rx(roll)^T Ry(pitch)^T (0, 0, 1) = (-sin p, sin r cos p, cos r cos p); optical x = -link y,
  // optical y = -link z, optical z = link x.
  const double sp = std::sin(c.pitch_rad), cp = std::cos(c.pitch_rad);
  const double sr = std::sin(c.roll_rad), cr = std::cos(c.roll_rad);
  return {-sr * cp, -cr * cp, -sp};
}

// The largest u . d over unit vectors d in the cone spanned by `edges` (in cyclic order, convex).
double max_over_cone(const Vec& u, const std::array<Vec, 4>& edges, double tan_h, double tan_v) {
  if (u[2] > 0.0 && std::abs(u[0]) <= u[2] * tan_h && std::abs(u[1]) <= u[2] * tan_v) return 1.0;
  double best = -1.0;
  for (std::size_t k = 0; k < edges.size(); ++k) {
    const Vec a = unit(edges[k]), b = unit(edges[(k + 1) % edges.size()]);
    best = std::max(best, dot(u, a));
    // On the face spanned by a and b: u projected onto its plane, when that direction lies between a and b.
    const Vec n = unit(cross(a, b));
    const Vec p = minus(u, scaled(n, dot(u, n)));
    const double ab = dot(a, b), det = 1.0 - ab * ab;
    const double alpha = (dot(a, p) - ab * dot(b, p)) / det, beta = (dot(b, p) - ab * dot(a, p)) / det;
    if (alpha >= 0.0 && beta >= 0.0) best = std::max(best, std::sqrt(dot(p, p)));
  }
  return best;
}

}  // namespace

double stvl_plane_depth(double radial_m, double hfov_rad, double vfov_rad) {
  return radial_m * std::cos(hfov_rad / 2.0) * std::cos(vfov_rad / 2.0);
}

double stvl_radial_for_depth(double depth_m, double hfov_rad, double vfov_rad) {
  return depth_m / (std::cos(hfov_rad / 2.0) * std::cos(vfov_rad / 2.0));
}

HeightRange stvl_frustum_heights(const CameraHeight& camera, double min_z_m, double max_z_m, double hfov_rad,
                                 double vfov_rad) {
  const Vec up = up_in_optical(camera);
  const double sh = std::sin(hfov_rad / 2.0), ch = std::cos(hfov_rad / 2.0);
  const double sv = std::sin(vfov_rad / 2.0), cv = std::cos(vfov_rad / 2.0);
  HeightRange r{camera.height_m, camera.height_m};
  bool first = true;
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0})
      for (double d : {min_z_m, max_z_m}) {
        // DepthCameraFrustum's corner ray Rx(+-v/2) Ry(+-h/2) Z = (+-sin(h/2), -+cos(h/2) sin(v/2), cos(h/2) cos(v/2)).
        const double z = camera.height_m + d * dot(up, {sx * sh, sy * ch * sv, ch * cv});
        r.min_m = first ? z : std::min(r.min_m, z);
        r.max_m = first ? z : std::max(r.max_m, z);
        first = false;
      }
  return r;
}

HeightRange view_heights(const CameraHeight& camera, double hfov_rad, double vfov_rad, double range_m) {
  const double th = std::tan(hfov_rad / 2.0), tv = std::tan(vfov_rad / 2.0);
  const std::array<Vec, 4> edges = {Vec{th, tv, 1.0}, Vec{th, -tv, 1.0}, Vec{-th, -tv, 1.0}, Vec{-th, tv, 1.0}};
  const Vec up = up_in_optical(camera);
  // Along each ray of the cone heights run from the optical centre's to range_m * (up . d).
  const double highest = max_over_cone(up, edges, th, tv);
  const double lowest = -max_over_cone(scaled(up, -1.0), edges, th, tv);
  return {camera.height_m + range_m * std::min(lowest, 0.0), camera.height_m + range_m * std::max(highest, 0.0)};
}

std::vector<HeightRange> uncovered(HeightRange range, std::vector<HeightRange> covers, double tolerance_m) {
  std::sort(covers.begin(), covers.end(), [](const HeightRange& a, const HeightRange& b) { return a.min_m < b.min_m; });
  std::vector<HeightRange> left;
  double from = range.min_m;
  for (const auto& c : covers) {
    if (c.min_m > from) left.push_back({from, std::min(c.min_m, range.max_m)});
    from = std::max(from, c.max_m);
    if (from >= range.max_m) break;
  }
  if (from < range.max_m) left.push_back({from, range.max_m});
  left.erase(std::remove_if(left.begin(), left.end(),
                            [&](const HeightRange& r) { return !(r.max_m - r.min_m > tolerance_m); }),
             left.end());
  return left;
}

}  // namespace stvl::config::lint_geometry

#include "truth/mesh_voxelize.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "truth/triangle_mesh.hpp"

namespace stvl::truth::detail {
namespace {

constexpr double kPad_m = 1e-9;   // closes the cubes against rounding, as for the other shapes
constexpr double kClip_m = 1e-6;  // candidate heights: generous, the exact test decides

struct Range {
  Eigen::Vector3i lo, hi;
  bool empty() const { return (hi.array() < lo.array()).any(); }
  double count() const {
    double n = 1;
    for (int i = 0; i < 3; ++i) n *= std::max(0, hi[i] - lo[i] + 1);
    return n;
  }
};

int index_of(double v, double s) { return static_cast<int>(std::floor(v / s)); }

Range range_of(const Eigen::AlignedBox3d& box, double s) {
  Range r;
  for (int i = 0; i < 3; ++i)
    r.lo[i] = index_of(box.min()[i] - kPad_m, s), r.hi[i] = index_of(box.max()[i] + kPad_m, s);
  return r;
}

Range intersect(const Range& a, const Range& b) { return {a.lo.cwiseMax(b.lo), a.hi.cwiseMin(b.hi)}; }

Eigen::AlignedBox3d box_of(const Triangle& t) {
  Eigen::AlignedBox3d b(t[0]);
  b.extend(t[1]).extend(t[2]);
  return b;
}

Eigen::AlignedBox3d cube(int x, int y, int z, double s) {
  const Eigen::Vector3d lo(x * s, y * s, z * s);
  return Eigen::AlignedBox3d(lo.array() - kPad_m, (lo.array() + s + kPad_m));
}

[[noreturn]] void too_many(const std::string& what, double n, const char* of, const std::vector<Triangle>& triangles) {
  Eigen::AlignedBox3d all;
  for (const Triangle& t : triangles) all.extend(box_of(t));
  char text[256];
  std::snprintf(text, sizeof text,
                ": %.3g candidate voxels (%s); its triangles span %.4g x %.4g x %.4g m (check the mesh's units and "
                "scale); restrict bounds_W or use a larger size",
                n, of, all.sizes().x(), all.sizes().y(), all.sizes().z());
  throw std::invalid_argument(what + text);
}

// The triangle clipped to the column [x0, x1] x [y0, y1] (Sutherland-Hodgman); its heights' range, or false.
bool heights_in_column(const Triangle& t, double x0, double x1, double y0, double y1, double* z0, double* z1) {
  Eigen::Vector3d poly[8], next[8];
  int n = 3;
  for (int i = 0; i < 3; ++i) poly[i] = t[i];
  const struct {
    int axis;
    double bound;
    double sign;
  } planes[4] = {{0, x0, 1}, {0, x1, -1}, {1, y0, 1}, {1, y1, -1}};
  for (const auto& plane : planes) {
    int m = 0;
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d& a = poly[i];
      const Eigen::Vector3d& b = poly[(i + 1) % n];
      const double da = plane.sign * (a[plane.axis] - plane.bound), db = plane.sign * (b[plane.axis] - plane.bound);
      if (da >= 0) next[m++] = a;
      if ((da >= 0) != (db >= 0)) next[m++] = a + (b - a) * (da / (da - db));
    }
    n = m;
    if (n == 0) return false;
    std::copy(next, next + n, poly);
  }
  *z0 = *z1 = poly[0].z();
  for (int i = 1; i < n; ++i) *z0 = std::min(*z0, poly[i].z()), *z1 = std::max(*z1, poly[i].z());
  return true;
}

struct Crossing {
  int x, y;
  double z;
  bool operator<(const Crossing& o) const { return x != o.x ? x < o.x : y != o.y ? y < o.y : z < o.z; }
};

// Crossings of every triangle with the vertical lines through the cell centres (moved by the generic offset) of
// columns in lo..hi (x, y); keep_z decides which crossings count.
template <typename Keep>
std::vector<Crossing> crossings(const std::vector<Triangle>& triangles, double s, const Eigen::Vector2i& lo,
                                const Eigen::Vector2i& hi, Keep keep_z) {
  const double ox = (0.5 + kColumnOffset) * s, oy = (0.5 + kColumnOffsetY) * s;
  std::vector<Crossing> out;
  for (const Triangle& t : triangles) {
    const Eigen::AlignedBox3d b = box_of(t);
    const int x0 = std::max(lo.x(), static_cast<int>(std::ceil((b.min().x() - ox) / s)));
    const int x1 = std::min(hi.x(), static_cast<int>(std::floor((b.max().x() - ox) / s)));
    const int y0 = std::max(lo.y(), static_cast<int>(std::ceil((b.min().y() - oy) / s)));
    const int y1 = std::min(hi.y(), static_cast<int>(std::floor((b.max().y() - oy) / s)));
    for (int x = x0; x <= x1; ++x)
      for (int y = y0; y <= y1; ++y) {
        double z;
        if (vertical_crossing(t[0], t[1], t[2], x * s + ox, y * s + oy, &z) && keep_z(z)) out.push_back({x, y, z});
      }
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

std::vector<VoxelKey> voxelize_triangles(const std::vector<Triangle>& triangles_W, bool closed, double s, bool solid,
                                         const Eigen::AlignedBox3d& region_W, const std::string& what) {
  std::vector<VoxelKey> out;
  if (region_W.isEmpty()) return out;
  const Range region = range_of(region_W, s);
  double candidates = 0;  // checked before anything is allocated
  for (const Triangle& t : triangles_W) {
    const Range r = intersect(range_of(box_of(t), s), region);
    if (!r.empty()) candidates += r.count();
  }
  if (candidates > kMaxCandidates) too_many(what, candidates, "the triangles' bounding boxes", triangles_W);
  const bool fill = solid && closed;
  if (fill && region.count() > kMaxCandidates) too_many(what, region.count(), "the solid's bounding box", triangles_W);

  for (const Triangle& t : triangles_W) {
    const Range r = intersect(range_of(box_of(t), s), region);
    for (int x = r.lo.x(); x <= r.hi.x(); ++x)
      for (int y = r.lo.y(); y <= r.hi.y(); ++y) {
        double z0, z1;
        if (!heights_in_column(t, x * s - kClip_m, (x + 1) * s + kClip_m, y * s - kClip_m, (y + 1) * s + kClip_m, &z0,
                               &z1))
          continue;
        const int zlo = std::max(r.lo.z(), index_of(z0 - kClip_m, s)),
                  zhi = std::min(r.hi.z(), index_of(z1 + kClip_m, s));
        for (int z = zlo; z <= zhi; ++z)
          if (triangle_meets_box(t[0], t[1], t[2], cube(x, y, z, s))) out.push_back({x, y, z});
      }
  }

  if (fill) {
    const auto cross = crossings(triangles_W, s, region.lo.head<2>(), region.hi.head<2>(), [](double) { return true; });
    for (std::size_t i = 0; i < cross.size();) {
      std::size_t j = i;
      while (j < cross.size() && cross[j].x == cross[i].x && cross[j].y == cross[i].y) ++j;
      // Voxel z is inside when an odd number of this column's crossings lie above its centre.
      const int zlo = std::max(region.lo.z(), index_of(cross[i].z, s));
      const int zhi = std::min(region.hi.z(), index_of(cross[j - 1].z, s));
      std::size_t below = i;
      for (int z = zlo; z <= zhi; ++z) {
        const double zc = (z + 0.5) * s;
        while (below < j && cross[below].z <= zc) ++below;
        if ((j - below) % 2 == 1) out.push_back({cross[i].x, cross[i].y, z});
      }
      i = j;
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::vector<CellKey> footprint_triangles(const std::vector<Triangle>& triangles_W, bool closed, double s,
                                         double min_z_m, double max_z_m, const std::string& what) {
  std::vector<CellKey> out;
  double candidates = 0;
  Eigen::AlignedBox3d all;
  for (const Triangle& t : triangles_W) {
    const Eigen::AlignedBox3d b = box_of(t);
    all.extend(b);
    if (b.max().z() < min_z_m - kPad_m || b.min().z() > max_z_m + kPad_m) continue;
    const Range r = range_of(b, s);
    candidates += double(r.hi.x() - r.lo.x() + 1) * double(r.hi.y() - r.lo.y() + 1);
  }
  if (candidates > kMaxCandidates)
    too_many(what, candidates, "footprint cells of the triangles' bounding boxes", triangles_W);
  for (const Triangle& t : triangles_W) {
    const Eigen::AlignedBox3d b = box_of(t);
    if (b.max().z() < min_z_m - kPad_m || b.min().z() > max_z_m + kPad_m) continue;
    const Range r = range_of(b, s);
    for (int x = r.lo.x(); x <= r.hi.x(); ++x)
      for (int y = r.lo.y(); y <= r.hi.y(); ++y) {
        const Eigen::AlignedBox3d column(Eigen::Vector3d(x * s - kPad_m, y * s - kPad_m, min_z_m - kPad_m),
                                         Eigen::Vector3d((x + 1) * s + kPad_m, (y + 1) * s + kPad_m, max_z_m + kPad_m));
        if (triangle_meets_box(t[0], t[1], t[2], column)) out.push_back({x, y});
      }
  }
  if (closed && !all.isEmpty()) {  // columns inside the solid through the whole band
    const Range r = range_of(all, s);
    const double columns = double(r.hi.x() - r.lo.x() + 1) * double(r.hi.y() - r.lo.y() + 1);
    if (columns > kMaxCandidates) too_many(what, columns, "footprint cells of the solid's bounding box", triangles_W);
    const double mid = 0.5 * (min_z_m + max_z_m);
    const auto cross = crossings(triangles_W, s, r.lo.head<2>(), r.hi.head<2>(), [&](double z) { return z > mid; });
    for (std::size_t i = 0; i < cross.size();) {
      std::size_t j = i;
      while (j < cross.size() && cross[j].x == cross[i].x && cross[j].y == cross[i].y) ++j;
      if ((j - i) % 2 == 1) out.push_back({cross[i].x, cross[i].y});
      i = j;
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace stvl::truth::detail

#include "robot_description/urdf_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace stvl::robot_description {
namespace {

constexpr int kCircleSides = 32;
constexpr double kStraight_m = 1e-4;

bool below(const mjModel* m, int body, int root) {
  for (; body > 0; body = m->body_parentid[body])
    if (body == root) return true;
  return body == root;
}

// A circle's outline on the floor: the corners of the 32-gon around it (circumscribed), in the plane normal to axis.
void add_circle(std::vector<Eigen::Vector2d>& out, const Eigen::Vector3d& centre, const Eigen::Vector3d& axis,
                double r) {
  const Eigen::Vector3d u = axis.unitOrthogonal(), v = axis.cross(u);
  const double R = r / std::cos(M_PI / kCircleSides);
  for (int i = 0; i < kCircleSides; ++i) {
    const double a = 2 * M_PI * i / kCircleSides;
    out.push_back((centre + R * (std::cos(a) * u + std::sin(a) * v)).head<2>());
  }
}

}  // namespace

RobotExtent robot_extent(const mjModel* m, const mjData* d, int root_body, const std::vector<int>& wheel_bodies) {
  RobotExtent e;
  e.lowest_z_m = e.wheels_lowest_z_m = std::numeric_limits<double>::infinity();
  std::vector<Eigen::Vector2d> outline;
  for (int g = 0; g < m->ngeom; ++g) {
    if (!below(m, m->geom_bodyid[g], root_body)) continue;
    const Eigen::Vector3d c(d->geom_xpos[3 * g], d->geom_xpos[3 * g + 1], d->geom_xpos[3 * g + 2]);
    const Eigen::Matrix3d R = Eigen::Map<const Eigen::Matrix<mjtNum, 3, 3, Eigen::RowMajor>>(d->geom_xmat + 9 * g);
    const mjtNum* size = m->geom_size + 3 * g;
    const Eigen::Vector3d axis = R.col(2);
    const double cos_up = std::min(1.0, std::abs(axis.z())), sin_up = std::sqrt(1.0 - cos_up * cos_up);
    double low = c.z();
    switch (m->geom_type[g]) {
      case mjGEOM_SPHERE:
        low -= size[0];
        add_circle(outline, c, Eigen::Vector3d::UnitZ(), size[0]);
        break;
      case mjGEOM_CAPSULE:
        low -= cos_up * size[1] + size[0];
        for (const double s : {-1.0, 1.0})
          add_circle(outline, c + s * size[1] * axis, Eigen::Vector3d::UnitZ(), size[0]);
        break;
      case mjGEOM_CYLINDER:
        low -= cos_up * size[1] + sin_up * size[0];
        for (const double s : {-1.0, 1.0}) add_circle(outline, c + s * size[1] * axis, axis, size[0]);
        break;
      case mjGEOM_ELLIPSOID:
      case mjGEOM_BOX: {
        const Eigen::Vector3d half(size[0], size[1], size[2]);
        low -= m->geom_type[g] == mjGEOM_BOX ? R.row(2).cwiseAbs().dot(half)
                                             : R.row(2).transpose().cwiseProduct(half).norm();
        for (int i = 0; i < 8; ++i)  // the box's corners (the ellipsoid's bounding box)
          outline.push_back(
              (c + R * half.cwiseProduct(Eigen::Vector3d(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1))).head<2>());
        break;
      }
      case mjGEOM_MESH: {
        const int mesh = m->geom_dataid[g];
        low = std::numeric_limits<double>::infinity();
        for (int v = m->mesh_vertadr[mesh]; v < m->mesh_vertadr[mesh] + m->mesh_vertnum[mesh]; ++v) {
          const Eigen::Vector3d p = c + R * Eigen::Vector3f(m->mesh_vert + 3 * v).cast<double>();
          low = std::min(low, p.z());
          outline.push_back(p.head<2>());
        }
        break;
      }
      default: continue;  // planes, height fields: not a robot's
    }
    if (low < e.lowest_z_m) {
      e.lowest_z_m = low;
      const char* name = mj_id2name(m, mjOBJ_GEOM, g);
      e.lowest_geom = name ? name : "geom " + std::to_string(g);
    }
    if (std::find(wheel_bodies.begin(), wheel_bodies.end(), m->geom_bodyid[g]) != wheel_bodies.end())
      e.wheels_lowest_z_m = std::min(e.wheels_lowest_z_m, low);
  }
  if (!std::isfinite(e.lowest_z_m)) e.lowest_z_m = 0;
  if (!std::isfinite(e.wheels_lowest_z_m)) e.wheels_lowest_z_m = e.lowest_z_m;
  e.footprint = convex_hull(std::move(outline));
  return e;
}

std::vector<Eigen::Vector2d> convex_hull(std::vector<Eigen::Vector2d> points) {
  std::sort(points.begin(), points.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  points.erase(std::unique(points.begin(), points.end()), points.end());
  if (points.size() < 3) return points;
  const auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
  };
  // Andrew's monotone chain: the lower hull left to right, then the upper hull right to left.
  std::vector<Eigen::Vector2d> hull(2 * points.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  // Corners that stand less than kStraight_m off the line through their neighbours (a wheel's rim seen edge-on,
  // rounded rotations) are no corners: dropped one at a time, the flattest first.
  while (hull.size() > 3) {
    std::size_t flattest = 0;
    double least = kStraight_m;
    for (std::size_t i = 0; i < hull.size(); ++i) {
      const Eigen::Vector2d& a = hull[(i + hull.size() - 1) % hull.size()];
      const Eigen::Vector2d& c = hull[(i + 1) % hull.size()];
      const double base = (c - a).norm();
      const double height = base > 0 ? std::abs(cross(a, hull[i], c)) / base : 0.0;
      if (height < least) least = height, flattest = i;
    }
    if (!(least < kStraight_m)) break;
    hull.erase(hull.begin() + static_cast<std::ptrdiff_t>(flattest));
  }
  return hull;
}

}  // namespace stvl::robot_description

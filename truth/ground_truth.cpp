#include "truth/ground_truth.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <unordered_map>

#include "truth/geom_meshes.hpp"
#include "truth/mesh_voxelize.hpp"

namespace stvl::truth {
namespace {

constexpr double kPad_m = 1e-9;  // closes voxel cubes against rounding of points on their faces

double box_sd(const Eigen::Vector3d& p, const Eigen::Vector3d& h) {
  const Eigen::Vector3d q = p.cwiseAbs() - h;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

Eigen::AlignedBox3d padded(const Eigen::AlignedBox3d& b, double pad) {
  return Eigen::AlignedBox3d(b.min().array() - pad, b.max().array() + pad);
}

// Separating axis test between an axis-aligned box and an oriented box.
bool aabb_meets_obb(const Eigen::AlignedBox3d& a, const Eigen::Isometry3d& T_obb, const Eigen::Vector3d& h_obb) {
  const Eigen::Vector3d ea = 0.5 * a.sizes();
  const Eigen::Vector3d t = T_obb.translation() - a.center();
  const Eigen::Matrix3d R = T_obb.linear();
  auto separated = [&](const Eigen::Vector3d& axis) {
    if (axis.squaredNorm() < 1e-18) return false;
    const double ra = ea.dot(axis.cwiseAbs());
    const double rb = h_obb.dot((R.transpose() * axis).cwiseAbs());
    return std::abs(t.dot(axis)) > ra + rb;
  };
  for (int i = 0; i < 3; ++i) {
    if (separated(Eigen::Vector3d::Unit(i)) || separated(R.col(i))) return false;
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (separated(Eigen::Vector3d::Unit(i).cross(R.col(j)))) return false;
  return true;
}

template <typename Fn>
void for_each_corner(const Eigen::AlignedBox3d& b, Fn fn) {
  for (int i = 0; i < 8; ++i) {
    fn(Eigen::Vector3d(i & 1 ? b.max().x() : b.min().x(), i & 2 ? b.max().y() : b.min().y(),
                       i & 4 ? b.max().z() : b.min().z()));
  }
}

struct IndexRange {
  Eigen::Vector3i lo, hi;
};

IndexRange index_range(const Eigen::AlignedBox3d& box, double size) {
  IndexRange r;
  for (int i = 0; i < 3; ++i) {
    r.lo[i] = static_cast<int>(std::floor((box.min()[i] - kPad_m) / size));
    r.hi[i] = static_cast<int>(std::floor((box.max()[i] + kPad_m) / size));
  }
  return r;
}

void check_size(double size_m, const char* what) {
  if (!(size_m > 0) || !std::isfinite(size_m)) {
    throw std::invalid_argument(std::string(what) + " " + std::to_string(size_m) + " must be > 0");
  }
}

void check_count(const IndexRange& r, const char* what) {
  double n = 1;
  for (int i = 0; i < 3; ++i) n *= std::max(0, r.hi[i] - r.lo[i] + 1);
  if (n > 2147483648.0) {
    throw std::invalid_argument(std::string(what) + ": " + std::to_string(n) +
                                " candidate voxels; restrict bounds_W or use a larger size");
  }
}

std::string name_of(const mjModel* m, int type, int id) {
  const char* name = mj_id2name(m, type, id);
  return name && *name ? name : "";
}

std::string geom_label(const sim::World& world, int g) {
  const mjModel* m = world.model();
  const std::string name = name_of(m, mjOBJ_GEOM, g);
  std::string label = name.empty() ? "geom " + std::to_string(g) : "geom '" + name + "'";
  label += " (";
  if (m->geom_type[g] == mjGEOM_MESH && m->geom_dataid[g] >= 0)
    label += "mesh '" + name_of(m, mjOBJ_MESH, m->geom_dataid[g]) + "', ";
  if (m->geom_type[g] == mjGEOM_HFIELD && m->geom_dataid[g] >= 0)
    label += "height field '" + name_of(m, mjOBJ_HFIELD, m->geom_dataid[g]) + "', ";
  return label + "body '" + world.body_name(m->geom_bodyid[g]) + "')";
}

bool in_groups(const mjModel* m, int g, unsigned group_mask) {
  const int group = m->geom_group[g];
  return group >= 0 && group < mjNGROUP && ((group_mask >> group) & 1u);
}

// The floor: a horizontal plane at or below 1 cm, left out on purpose.
bool is_floor(const mjData* d, int g) {
  return std::abs(d->geom_xmat[9 * g + 8]) > 1 - 1e-9 && d->geom_xpos[3 * g + 2] <= 0.01;
}
// Drivable ground (a ramp, a raised floor): a geom whose name starts with "floor", left out like the floor.
bool is_ground(const mjModel* m, int g) {
  const char* name = mj_id2name(m, mjOBJ_GEOM, g);
  return name != nullptr && std::strncmp(name, "floor", 5) == 0;
}

Eigen::Isometry3d pose_of(const mjData* d, int g) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    T.translation()[r] = d->geom_xpos[3 * g + r];
    for (int c = 0; c < 3; ++c) T.linear()(r, c) = d->geom_xmat[9 * g + 3 * r + c];
  }
  return T;
}

std::vector<detail::Triangle> triangles_W(const ObstacleGeom& geom) {
  std::vector<detail::Triangle> out(geom.mesh->faces().size());
  for (std::size_t f = 0; f < out.size(); ++f) {
    const auto t = geom.mesh->triangle(f);
    out[f] = {geom.T_world_geom * t[0], geom.T_world_geom * t[1], geom.T_world_geom * t[2]};
  }
  return out;
}

}  // namespace

Eigen::AlignedBox3d ObstacleGeom::aabb_W() const {
  const Eigen::Matrix3d R = T_world_geom.linear();
  Eigen::Vector3d half = Eigen::Vector3d::Zero();
  switch (shape) {
    case ShapeType::sphere: half.setConstant(size_m.x()); break;
    case ShapeType::capsule: half = R.col(2).cwiseAbs() * size_m.y() + Eigen::Vector3d::Constant(size_m.x()); break;
    case ShapeType::cylinder: half = R.cwiseAbs() * Eigen::Vector3d(size_m.x(), size_m.x(), size_m.y()); break;
    case ShapeType::ellipsoid:
      for (int i = 0; i < 3; ++i) half[i] = R.row(i).cwiseProduct(size_m.transpose()).norm();
      break;
    case ShapeType::box: half = R.cwiseAbs() * size_m; break;
    case ShapeType::mesh: {   // tight: MuJoCo turns meshes to their principal axes, so the box of the geom
      Eigen::AlignedBox3d b;  // frame's box would be loose
      for (const auto& v : mesh->vertices()) b.extend(T_world_geom * v);
      return b;
    }
  }
  return Eigen::AlignedBox3d(T_world_geom.translation() - half, T_world_geom.translation() + half);
}

double ObstacleGeom::signed_distance_m(const Eigen::Vector3d& p_W) const {
  const Eigen::Vector3d p = T_world_geom.inverse() * p_W;
  switch (shape) {
    case ShapeType::box: return box_sd(p, size_m);
    case ShapeType::sphere: return p.norm() - size_m.x();
    case ShapeType::capsule:
      return (p - Eigen::Vector3d(0, 0, std::clamp(p.z(), -size_m.y(), size_m.y()))).norm() - size_m.x();
    case ShapeType::cylinder: {
      const Eigen::Vector2d d(p.head<2>().norm() - size_m.x(), std::abs(p.z()) - size_m.y());
      return d.cwiseMax(0.0).norm() + std::min(d.maxCoeff(), 0.0);
    }
    case ShapeType::ellipsoid: return size_m.minCoeff() * (p.cwiseQuotient(size_m).norm() - 1.0);
    case ShapeType::mesh: {
      const double d = mesh->distance_m(p);
      return mesh->inside(p) ? -d : d;
    }
  }
  return 0.0;
}

bool ObstacleGeom::intersects_solid(const Eigen::AlignedBox3d& box_W, double tolerance_m) const {
  const Eigen::AlignedBox3d box = padded(box_W, kPad_m);
  if (shape == ShapeType::mesh)
    return mesh->meets_box(T_world_geom, box) || mesh->inside(T_world_geom.inverse() * box.center());
  if (shape == ShapeType::box) return aabb_meets_obb(box, T_world_geom, size_m);
  if (shape == ShapeType::sphere) {
    const Eigen::Vector3d c = T_world_geom.translation();
    return (c.cwiseMax(box.min()).cwiseMin(box.max()) - c).norm() <= size_m.x();
  }
  const double d = signed_distance_m(box.center());
  const double half_diagonal = 0.5 * box.sizes().norm();
  if (d <= 0.0) return true;
  if (d > half_diagonal) return false;
  if (half_diagonal <= tolerance_m) return true;
  int axis = 0;
  box.sizes().maxCoeff(&axis);
  Eigen::AlignedBox3d lower = box_W, upper = box_W;
  const double mid = box_W.center()[axis];
  lower.max()[axis] = mid;
  upper.min()[axis] = mid;
  return intersects_solid(lower, tolerance_m) || intersects_solid(upper, tolerance_m);
}

bool ObstacleGeom::contains_box(const Eigen::AlignedBox3d& box_W) const {
  if (shape == ShapeType::mesh) {
    const Eigen::AlignedBox3d box = padded(box_W, kPad_m);
    return mesh->closed() && !mesh->meets_box(T_world_geom, box) && mesh->inside(T_world_geom.inverse() * box.center());
  }
  bool inside = true;
  for_each_corner(padded(box_W, kPad_m),
                  [&](const Eigen::Vector3d& p) { inside = inside && signed_distance_m(p) <= 0.0; });
  return inside;
}

std::vector<ObstacleGeom> obstacle_geoms(const sim::World& world, unsigned group_mask) {
  const mjModel* m = world.model();
  const mjData* d = world.data();
  std::vector<ObstacleGeom> out;
  for (int g = 0; g < m->ngeom; ++g) {
    if (!in_groups(m, g, group_mask) || is_ground(m, g)) continue;
    ObstacleGeom geom;
    geom.geom_id = g;
    geom.body_id = m->geom_bodyid[g];
    geom.body_name = world.body_name(geom.body_id);
    geom.T_world_geom = pose_of(d, g);
    const Eigen::Vector3d size(m->geom_size[3 * g], m->geom_size[3 * g + 1], m->geom_size[3 * g + 2]);
    switch (m->geom_type[g]) {
      case mjGEOM_BOX:
        geom.shape = ShapeType::box;
        geom.size_m = size;
        break;
      case mjGEOM_SPHERE:
        geom.shape = ShapeType::sphere;
        geom.size_m = size;
        break;
      case mjGEOM_CAPSULE:
        geom.shape = ShapeType::capsule;
        geom.size_m = size;
        break;
      case mjGEOM_CYLINDER:
        geom.shape = ShapeType::cylinder;
        geom.size_m = size;
        break;
      case mjGEOM_ELLIPSOID:
        geom.shape = ShapeType::ellipsoid;
        geom.size_m = size;
        break;
      case mjGEOM_MESH:
        if (m->geom_dataid[g] < 0) continue;
        geom.label = geom_label(world, g);
        geom.mesh = model_mesh(m, m->geom_dataid[g], geom.label);
        break;
      case mjGEOM_HFIELD:
        if (m->geom_dataid[g] < 0) continue;
        geom.label = geom_label(world, g);
        geom.mesh = height_field_mesh(m, m->geom_dataid[g], geom.label);
        break;
      case mjGEOM_PLANE:
        if (is_floor(d, g) || !(size.x() > 0 && size.y() > 0)) continue;  // the floor; infinite: truth_notes()
        geom.label = geom_label(world, g);
        geom.mesh = rectangle_mesh(size.x(), size.y(), geom.label);
        break;
      default: continue;
    }
    if (geom.mesh) {
      geom.shape = ShapeType::mesh;
      geom.size_m = 0.5 * geom.mesh->aabb_G().sizes();
    } else {
      geom.label = geom_label(world, g);
    }
    out.push_back(std::move(geom));
  }
  return out;
}

void refresh_poses(const sim::World& world, std::vector<ObstacleGeom>& geoms) {
  for (ObstacleGeom& geom : geoms) {
    if (geom.geom_id < 0 || geom.geom_id >= world.model()->ngeom)
      throw std::invalid_argument("refresh_poses: geom id " + std::to_string(geom.geom_id) + " is not in the model");
    geom.T_world_geom = pose_of(world.data(), geom.geom_id);
  }
}

bool poses_decide_membership(const sim::World& world, unsigned group_mask) {
  const mjModel* m = world.model();
  for (int g = 0; g < m->ngeom; ++g) {
    const int b = m->geom_bodyid[g];
    if (in_groups(m, g, group_mask) && m->geom_type[g] == mjGEOM_PLANE &&
        (m->body_mocapid[b] >= 0 || m->body_weldid[b] != 0))
      return true;
  }
  return false;
}

std::vector<TruthNote> truth_notes(const sim::World& world, unsigned group_mask) {
  const mjModel* m = world.model();
  const mjData* d = world.data();
  std::vector<TruthNote> out;
  for (const ObstacleGeom& geom : obstacle_geoms(world, group_mask))
    if (m->geom_type[geom.geom_id] == mjGEOM_MESH && !geom.mesh->closed())
      out.push_back(
          {geom.geom_id, geom.label,
           geom.label + " is not closed (" + std::to_string(geom.mesh->open_edges()) +
               " edges without a partner face): its solid is taken as its surface (footprint cells, solid voxels)"});
  for (int g = 0; g < m->ngeom; ++g)
    if (in_groups(m, g, group_mask) && m->geom_type[g] == mjGEOM_PLANE && !is_floor(d, g) &&
        !(m->geom_size[3 * g] > 0 && m->geom_size[3 * g + 1] > 0)) {
      const std::string label = geom_label(world, g);
      out.push_back({g, label, label + " is an infinite plane that is not the floor: left out of the truth"});
    }
  return out;
}

std::vector<VoxelKey> voxelize(const ObstacleGeom& geom, const VoxelizeOptions& options) {
  const double s = options.voxel_size_m;
  check_size(s, "voxel_size_m");
  if (!(options.tolerance_fraction > 0)) throw std::invalid_argument("tolerance_fraction must be > 0");
  if (options.bounds_W.isEmpty()) throw std::invalid_argument("voxelize: bounds_W is empty");
  const Eigen::AlignedBox3d region = geom.aabb_W().intersection(options.bounds_W);
  std::vector<VoxelKey> out;
  if (region.isEmpty()) return out;
  if (geom.shape == ShapeType::mesh)
    return detail::voxelize_triangles(triangles_W(geom), geom.mesh->closed(), s, options.solid, region,
                                      "voxelize: " + geom.label);
  const IndexRange r = index_range(region, s);
  check_count(r, "voxelize");
  const double tolerance = options.tolerance_fraction * s;
  const double half_diagonal = 0.5 * std::sqrt(3.0) * s;
  for (int x = r.lo.x(); x <= r.hi.x(); ++x)
    for (int y = r.lo.y(); y <= r.hi.y(); ++y)
      for (int z = r.lo.z(); z <= r.hi.z(); ++z) {
        const Eigen::Vector3d lo(x * s, y * s, z * s);
        const Eigen::AlignedBox3d cube(lo, lo + Eigen::Vector3d::Constant(s));
        const double d = geom.signed_distance_m(cube.center());  // quick accept/reject first
        if (d > half_diagonal) continue;
        bool keep;
        if (options.solid) {
          keep = d <= 0.0 || geom.intersects_solid(cube, tolerance);
        } else {
          // Every shape here is convex: a cube whose centre is outside (d > 0) is not inside, and contains_box()
          // (eight distances) would say so. tests/truth checks the implication.
          keep = d >= -half_diagonal && geom.intersects_solid(cube, tolerance) && (d > 0.0 || !geom.contains_box(cube));
        }
        if (keep) out.push_back({x, y, z});
      }
  return out;  // generated in sorted order
}

std::vector<BodyVoxels> voxelize_bodies(const std::vector<ObstacleGeom>& geoms, const VoxelizeOptions& options) {
  std::vector<BodyVoxels> out;
  std::unordered_map<int, std::size_t> index_of_body;
  for (const auto& geom : geoms) {
    auto [it, inserted] = index_of_body.emplace(geom.body_id, out.size());
    if (inserted) out.push_back({geom.body_id, geom.body_name, {}});
    auto voxels = voxelize(geom, options);
    auto& dst = out[it->second].voxels;
    dst.insert(dst.end(), voxels.begin(), voxels.end());
  }
  for (auto& body : out) {
    std::sort(body.voxels.begin(), body.voxels.end());
    body.voxels.erase(std::unique(body.voxels.begin(), body.voxels.end()), body.voxels.end());
  }
  return out;
}

VoxelSet merge(const std::vector<BodyVoxels>& bodies) {
  VoxelSet out;
  for (const auto& body : bodies) out.insert(body.voxels.begin(), body.voxels.end());
  return out;
}

std::vector<BodyFootprint> footprints(const std::vector<ObstacleGeom>& geoms, double cell_size_m, double min_z_m,
                                      double max_z_m, double tolerance_fraction) {
  check_size(cell_size_m, "cell_size_m");
  if (!(min_z_m < max_z_m)) {
    throw std::invalid_argument("footprint height band [" + std::to_string(min_z_m) + ", " + std::to_string(max_z_m) +
                                "] is empty");
  }
  if (!(tolerance_fraction > 0)) throw std::invalid_argument("tolerance_fraction must be > 0");
  const double s = cell_size_m;
  std::vector<BodyFootprint> out;
  std::unordered_map<int, std::size_t> index_of_body;
  for (const auto& geom : geoms) {
    auto [it, inserted] = index_of_body.emplace(geom.body_id, out.size());
    if (inserted) out.push_back({geom.body_id, geom.body_name, {}});
    if (geom.shape == ShapeType::mesh) {
      const auto cells = detail::footprint_triangles(triangles_W(geom), geom.mesh->closed(), s, min_z_m, max_z_m,
                                                     "footprints: " + geom.label);
      out[it->second].cells.insert(out[it->second].cells.end(), cells.begin(), cells.end());
      continue;
    }
    const Eigen::AlignedBox3d aabb = geom.aabb_W();
    const double z0 = std::max(min_z_m, aabb.min().z()), z1 = std::min(max_z_m, aabb.max().z());
    if (z0 > z1) continue;
    const IndexRange r = index_range(aabb, s);
    check_count(r, "footprints");
    auto& cells = out[it->second].cells;
    for (int x = r.lo.x(); x <= r.hi.x(); ++x)
      for (int y = r.lo.y(); y <= r.hi.y(); ++y) {
        const Eigen::AlignedBox3d column(Eigen::Vector3d(x * s, y * s, z0),
                                         Eigen::Vector3d((x + 1) * s, (y + 1) * s, z1));
        if (geom.intersects_solid(column, tolerance_fraction * s)) cells.push_back({x, y});
      }
  }
  for (auto& body : out) {
    std::sort(body.cells.begin(), body.cells.end());
    body.cells.erase(std::unique(body.cells.begin(), body.cells.end()), body.cells.end());
  }
  return out;
}

RayHit cast_ray(const sim::World& world, const Eigen::Vector3d& origin_W, const Eigen::Vector3d& direction_W,
                double max_range_m, unsigned group_mask, int exclude_body_id) {
  const double n = direction_W.norm();
  if (!origin_W.allFinite() || !std::isfinite(n) || n < 1e-12) {
    throw std::invalid_argument("cast_ray: origin must be finite and direction non-zero");
  }
  std::array<mjtByte, mjNGROUP> groups{};
  for (int g = 0; g < mjNGROUP; ++g) groups[g] = (group_mask >> g) & 1u;
  const Eigen::Vector3d u = direction_W / n;
  const mjtNum pnt[3] = {origin_W.x(), origin_W.y(), origin_W.z()};
  const mjtNum vec[3] = {u.x(), u.y(), u.z()};
  int geom_id = -1;
  const double x = mj_ray(world.model(), world.data(), pnt, vec, groups.data(), 1, exclude_body_id, &geom_id);
  RayHit hit;
  if (x < 0 || geom_id < 0 || x > max_range_m) return hit;
  hit.hit = true;
  hit.distance_m = x;
  hit.geom_id = geom_id;
  hit.body_id = world.model()->geom_bodyid[geom_id];
  hit.body_name = world.body_name(hit.body_id);
  return hit;
}

}  // namespace stvl::truth

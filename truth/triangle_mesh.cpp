#include "truth/triangle_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace stvl::truth {
namespace {

constexpr int kLeafFaces = 4;

// Sign of the side of (x, y) from the edge u -> v in the xy plane, with its magnitude (twice the area): evaluated
// from the lexicographically smaller endpoint so that both faces of a shared edge get the same number; exactly on
// the line counts as left of the canonical direction.
double edge_value(const Eigen::Vector3d& u, const Eigen::Vector3d& v, double x, double y, bool* positive) {
  const bool swap = v.x() < u.x() || (v.x() == u.x() && v.y() < u.y());
  const Eigen::Vector3d& p = swap ? v : u;
  const Eigen::Vector3d& q = swap ? u : v;
  const double e = (q.x() - p.x()) * (y - p.y()) - (q.y() - p.y()) * (x - p.x());
  *positive = (e >= 0) != swap;
  return swap ? -e : e;
}

// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                    const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double sum = va + vb + vc;
  if (!(std::abs(sum) > 0)) {  // degenerate: nearest of the three edges
    auto on_segment = [&](const Eigen::Vector3d& s, const Eigen::Vector3d& t) {
      const Eigen::Vector3d d = t - s;
      const double n = d.squaredNorm();
      return n > 0 ? Eigen::Vector3d(s + d * std::clamp((p - s).dot(d) / n, 0.0, 1.0)) : s;
    };
    Eigen::Vector3d best = on_segment(a, b);
    for (const auto& q : {on_segment(b, c), on_segment(c, a)})
      if ((q - p).squaredNorm() < (best - p).squaredNorm()) best = q;
    return best;
  }
  const double v = vb / sum, w = vc / sum;
  return a + ab * v + ac * w;
}

}  // namespace

bool triangle_meets_box(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                        const Eigen::AlignedBox3d& box) {
  const Eigen::Vector3d centre = box.center();
  const Eigen::Vector3d h = 0.5 * box.sizes();
  const Eigen::Vector3d v0 = a - centre, v1 = b - centre, v2 = c - centre;
  for (int i = 0; i < 3; ++i)  // the box's face normals
    if (std::min({v0[i], v1[i], v2[i]}) > h[i] || std::max({v0[i], v1[i], v2[i]}) < -h[i]) return false;
  const Eigen::Vector3d edges[3] = {v1 - v0, v2 - v1, v0 - v2};
  auto separated = [&](const Eigen::Vector3d& axis) {
    const double p0 = v0.dot(axis), p1 = v1.dot(axis), p2 = v2.dot(axis);
    const double r = h.dot(axis.cwiseAbs());
    return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
  };
  for (const auto& e : edges)  // the nine edge-by-axis cross products
    for (int i = 0; i < 3; ++i)
      if (separated(Eigen::Vector3d::Unit(i).cross(e))) return false;
  const Eigen::Vector3d n = edges[0].cross(edges[1]);  // the triangle's plane
  return std::abs(n.dot(v0)) <= h.dot(n.cwiseAbs());
}

bool vertical_crossing(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, double x, double y,
                       double* z_m) {
  bool pa, pb, pc;
  const double wa = edge_value(b, c, x, y, &pa);  // weight of a: the side of bc
  const double wb = edge_value(c, a, x, y, &pb);
  const double wc = edge_value(a, b, x, y, &pc);
  if (pa != pb || pb != pc) return false;
  const double sum = wa + wb + wc;  // twice the projected area, signed
  if (sum == 0) return false;       // edge-on
  *z_m = (wa * a.z() + wb * b.z() + wc * c.z()) / sum;
  return true;
}

TriangleMesh::TriangleMesh(std::vector<Eigen::Vector3d> vertices_G, std::vector<Face> faces, const std::string& what)
    : vertices_(std::move(vertices_G)), faces_(std::move(faces)) {
  if (faces_.empty()) throw std::invalid_argument(what + " has no faces");
  for (std::size_t v = 0; v < vertices_.size(); ++v)
    if (!vertices_[v].allFinite())
      throw std::invalid_argument(what + ": vertex " + std::to_string(v) + " is not finite");
  const int n = static_cast<int>(vertices_.size());
  for (const Face& f : faces_)
    for (int i : f)
      if (i < 0 || i >= n) throw std::invalid_argument(what + ": vertex index " + std::to_string(i) + " out of range");

  // Weld vertices at equal positions (MuJoCo keeps an OBJ's vertices once per face corner), then count edges.
  std::vector<int> by_position(vertices_.size()), weld(vertices_.size());
  std::iota(by_position.begin(), by_position.end(), 0);
  auto less = [&](int i, int j) {
    const auto &p = vertices_[i], &q = vertices_[j];
    return p.x() != q.x() ? p.x() < q.x() : p.y() != q.y() ? p.y() < q.y() : p.z() < q.z();
  };
  std::sort(by_position.begin(), by_position.end(), less);
  for (std::size_t k = 0; k < by_position.size(); ++k)
    weld[by_position[k]] = k > 0 && vertices_[by_position[k]] == vertices_[by_position[k - 1]]
                               ? weld[by_position[k - 1]]
                               : static_cast<int>(k);
  std::vector<std::uint64_t> edges;
  edges.reserve(3 * faces_.size());
  for (const Face& f : faces_)
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t u = weld[f[i]], v = weld[f[(i + 1) % 3]];
      if (u != v) edges.push_back(static_cast<std::uint64_t>(std::min(u, v)) << 32 | std::max(u, v));
    }
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    open_edges_ += (j - i) % 2;
    i = j;
  }

  std::vector<Eigen::Vector3d> centroids(faces_.size());
  for (std::size_t f = 0; f < faces_.size(); ++f) {
    const auto t = triangle(f);
    centroids[f] = (t[0] + t[1] + t[2]) / 3.0;
    for (const auto& p : t) aabb_.extend(p);
  }
  order_.resize(faces_.size());
  std::iota(order_.begin(), order_.end(), 0);
  nodes_.reserve(2 * faces_.size() / kLeafFaces + 1);
  build(0, static_cast<int>(faces_.size()), centroids);
}

int TriangleMesh::build(int first, int count, const std::vector<Eigen::Vector3d>& centroids) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.push_back({});
  Eigen::AlignedBox3d box, centres;
  for (int k = first; k < first + count; ++k) {
    for (const auto& p : triangle(order_[k])) box.extend(p);
    centres.extend(centroids[order_[k]]);
  }
  nodes_[index].box = box;
  if (count <= kLeafFaces) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  int axis = 0;
  centres.sizes().maxCoeff(&axis);
  const int half = count / 2;
  std::nth_element(order_.begin() + first, order_.begin() + first + half, order_.begin() + first + count,
                   [&](int i, int j) { return centroids[i][axis] < centroids[j][axis]; });
  build(first, half, centroids);
  const int right = build(first + half, count - half, centroids);
  nodes_[index].right = right;
  return index;
}

template <typename Enter, typename Visit>
void TriangleMesh::traverse(Enter enter, Visit visit) const {
  int stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (!enter(node.box)) continue;
    if (node.right < 0) {
      for (int k = node.first; k < node.first + node.count; ++k)
        if (!visit(order_[k])) return;
    } else {
      stack[top++] = node.right;
      stack[top++] = static_cast<int>(&node - nodes_.data()) + 1;
    }
  }
}

double TriangleMesh::distance_m(const Eigen::Vector3d& p) const {
  double best2 = std::numeric_limits<double>::infinity();
  traverse([&](const Eigen::AlignedBox3d& box) { return box.squaredExteriorDistance(p) < best2; },
           [&](int f) {
             const auto t = triangle(f);
             best2 = std::min(best2, (closest_on_triangle(p, t[0], t[1], t[2]) - p).squaredNorm());
             return true;
           });
  return std::sqrt(best2);
}

bool TriangleMesh::inside(const Eigen::Vector3d& p) const {
  if (!closed()) return false;
  const double x = p.x() + kInsideOffset_m, y = p.y() + kInsideOffset_m;
  bool odd = false;
  traverse(
      [&](const Eigen::AlignedBox3d& box) {
        return box.min().x() <= x && x <= box.max().x() && box.min().y() <= y && y <= box.max().y() &&
               box.max().z() > p.z();
      },
      [&](int f) {
        const auto t = triangle(f);
        double z;
        if (vertical_crossing(t[0], t[1], t[2], x, y, &z) && z > p.z()) odd = !odd;
        return true;
      });
  return odd;
}

bool TriangleMesh::meets_box(const Eigen::Isometry3d& T_W_G, const Eigen::AlignedBox3d& box_W) const {
  Eigen::AlignedBox3d box_G;  // the world box's bounds in the mesh frame
  const Eigen::Isometry3d T_G_W = T_W_G.inverse();
  for (int i = 0; i < 8; ++i)
    box_G.extend(T_G_W * Eigen::Vector3d(i & 1 ? box_W.max().x() : box_W.min().x(),
                                         i & 2 ? box_W.max().y() : box_W.min().y(),
                                         i & 4 ? box_W.max().z() : box_W.min().z()));
  box_G = Eigen::AlignedBox3d(box_G.min().array() - 1e-9, box_G.max().array() + 1e-9);  // rounding of the turn
  bool hit = false;
  traverse([&](const Eigen::AlignedBox3d& box) { return box.intersects(box_G); },
           [&](int f) {
             const auto t = triangle(f);
             hit = triangle_meets_box(T_W_G * t[0], T_W_G * t[1], T_W_G * t[2], box_W);
             return !hit;
           });
  return hit;
}

}  // namespace stvl::truth

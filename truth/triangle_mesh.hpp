#pragma once
// Triangles of a mesh or height field in one frame (a geom's, G), with the exact predicates the ground truth needs:
// a closed axis-aligned box against a triangle (separating axes, after Akenine-Möller), the crossing of a vertical
// line with a triangle (robust on shared edges and vertices), distance, inside and box queries through a bounding
// volume hierarchy. No MuJoCo here: truth/ground_truth.cpp reads the model, truth/reference/ checks the voxelization.
#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace stvl::truth {

// Whether the closed box meets the closed triangle abc (exact up to rounding; no tolerance). Degenerate
// triangles (segments, points) are handled.
bool triangle_meets_box(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                        const Eigen::AlignedBox3d& box);

// Whether the vertical line through (x, y) crosses triangle abc; *z_m gets the height of the crossing. Each edge is
// evaluated in a canonical vertex order, and a line exactly on an edge belongs to the side left of the edge's
// canonical direction, so two faces sharing an edge or a vertex never both or neither claim a line that passes
// between them: parity counts along the line are consistent on a closed mesh. Triangles seen edge-on are never
// crossed.
bool vertical_crossing(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, double x, double y,
                       double* z_m);

class TriangleMesh {
 public:
  using Face = std::array<int, 3>;
  // Throws std::invalid_argument naming `what` for no faces, a non-finite vertex or an index out of range.
  TriangleMesh(std::vector<Eigen::Vector3d> vertices_G, std::vector<Face> faces, const std::string& what);

  const std::vector<Eigen::Vector3d>& vertices() const { return vertices_; }
  const std::vector<Face>& faces() const { return faces_; }
  std::array<Eigen::Vector3d, 3> triangle(std::size_t f) const {
    return {vertices_[faces_[f][0]], vertices_[faces_[f][1]], vertices_[faces_[f][2]]};
  }
  const Eigen::AlignedBox3d& aabb_G() const { return aabb_; }
  // Closed: after merging vertices at equal positions, every edge is shared by an even number of faces, so the
  // parity of crossings tells inside from outside (a watertight surface; shells may nest or touch).
  bool closed() const { return open_edges_ == 0; }
  std::size_t open_edges() const { return open_edges_; }

  // Distance from p_G to the nearest triangle (unsigned).
  double distance_m(const Eigen::Vector3d& p_G) const;
  // Whether p_G is inside (closed meshes; always false for open ones): odd number of crossings above it on the
  // vertical line through p_G moved by kInsideOffset_m in x and y (a generic offset: lines through vertices
  // become improbable; only points within that offset of the surface can be misjudged).
  bool inside(const Eigen::Vector3d& p_G) const;
  // Whether some triangle, placed by T_W_G, meets the closed world box.
  bool meets_box(const Eigen::Isometry3d& T_W_G, const Eigen::AlignedBox3d& box_W) const;

  static constexpr double kInsideOffset_m = 3.7e-9;

 private:
  struct Node {
    Eigen::AlignedBox3d box;
    int first = 0, count = 0;  // leaf: order_[first, first + count)
    int right = -1;            // inner node: left child is the next node
  };
  int build(int first, int count, const std::vector<Eigen::Vector3d>& centroids);
  template <typename Enter, typename Visit>
  void traverse(Enter enter, Visit visit) const;

  std::vector<Eigen::Vector3d> vertices_;
  std::vector<Face> faces_;
  Eigen::AlignedBox3d aabb_;
  std::size_t open_edges_ = 0;
  std::vector<int> order_;  // faces in leaf order
  std::vector<Node> nodes_;
};

}  // namespace stvl::truth

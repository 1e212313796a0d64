#include "truth/geom_meshes.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <unordered_map>

namespace stvl::truth {
namespace {

struct Hash64 {
  std::uint64_t h = 0x9E3779B97F4A7C15ull;
  void add(const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (; bytes >= 8; bytes -= 8, p += 8) {
      std::uint64_t w;
      std::memcpy(&w, p, 8);
      mix(w);
    }
    std::uint64_t tail = 0;
    std::memcpy(&tail, p, bytes);
    mix(tail ^ (static_cast<std::uint64_t>(bytes) << 56));
  }
  void mix(std::uint64_t w) {
    h = (h ^ w) * 0xBF58476D1CE4E5B9ull;
    h ^= h >> 31;
  }
};

template <typename Build>
std::shared_ptr<const TriangleMesh> cached_mesh(std::uint64_t key, Build build) {
  static std::mutex mutex;
  static std::unordered_map<std::uint64_t, std::weak_ptr<const TriangleMesh>> cache;
  std::lock_guard<std::mutex> lock(mutex);
  if (auto it = cache.find(key); it != cache.end())
    if (auto mesh = it->second.lock()) return mesh;
  for (auto it = cache.begin(); it != cache.end();) it = it->second.expired() ? cache.erase(it) : std::next(it);
  auto mesh = build();
  cache[key] = mesh;
  return mesh;
}

}  // namespace

std::shared_ptr<const TriangleMesh> model_mesh(const mjModel* m, int id, const std::string& label) {
  const int nv = m->mesh_vertnum[id], nf = m->mesh_facenum[id];
  const float* vert = m->mesh_vert + 3 * m->mesh_vertadr[id];
  const int* face = m->mesh_face + 3 * m->mesh_faceadr[id];
  Hash64 key;
  key.add("mesh", 4);
  key.add(&nv, sizeof nv);
  key.add(&nf, sizeof nf);
  key.add(vert, 3 * sizeof(float) * std::max(nv, 0));
  key.add(face, 3 * sizeof(int) * std::max(nf, 0));
  return cached_mesh(key.h, [&] {
    std::vector<Eigen::Vector3d> vertices(std::max(nv, 0));
    for (int v = 0; v < nv; ++v) vertices[v] = Eigen::Vector3d(vert[3 * v], vert[3 * v + 1], vert[3 * v + 2]);
    std::vector<TriangleMesh::Face> faces(std::max(nf, 0));
    for (int f = 0; f < nf; ++f) faces[f] = {face[3 * f], face[3 * f + 1], face[3 * f + 2]};
    return std::make_shared<const TriangleMesh>(std::move(vertices), std::move(faces), label);
  });
}

// The base is split like the grid, so that every edge is shared.
std::shared_ptr<const TriangleMesh> height_field_mesh(const mjModel* m, int id, const std::string& label) {
  const int nr = m->hfield_nrow[id], nc = m->hfield_ncol[id];
  const float* data = m->hfield_data + m->hfield_adr[id];
  float sz[4];
  for (int i = 0; i < 4; ++i) sz[i] = static_cast<float>(m->hfield_size[4 * id + i]);
  Hash64 key;
  key.add("hfield", 6);
  key.add(&nr, sizeof nr);
  key.add(&nc, sizeof nc);
  key.add(sz, sizeof sz);
  key.add(data, sizeof(float) * std::max(nr * nc, 0));
  return cached_mesh(key.h, [&] {
    if (nr < 2 || nc < 2) throw std::invalid_argument(label + ": a height field needs at least 2 x 2 samples");
    const float width = 0.5f * (nc - 1), height = 0.5f * (nr - 1);
    std::vector<Eigen::Vector3d> vertices(2 * nr * nc);
    auto top = [&](int r, int c) { return r * nc + c; };
    auto base = [&](int r, int c) { return nr * nc + r * nc + c; };
    for (int r = 0; r < nr; ++r)
      for (int c = 0; c < nc; ++c) {
        const float x = sz[0] * (c / width - 1.0f), y = sz[1] * (r / height - 1.0f);
        vertices[top(r, c)] = Eigen::Vector3d(x, y, data[r * nc + c] * sz[2]);
        vertices[base(r, c)] = Eigen::Vector3d(x, y, -sz[3]);
      }
    std::vector<TriangleMesh::Face> faces;
    faces.reserve(4 * (nr - 1) * (nc - 1) + 4 * (nr - 1) + 4 * (nc - 1));
    for (int layer = 0; layer < 2; ++layer) {
      auto at = [&](int r, int c) { return layer * nr * nc + r * nc + c; };
      for (int r = 0; r + 1 < nr; ++r)
        for (int c = 0; c + 1 < nc; ++c) {
          faces.push_back({at(r + 1, c), at(r, c), at(r + 1, c + 1)});
          faces.push_back({at(r, c), at(r + 1, c + 1), at(r, c + 1)});
        }
    }
    auto side = [&](int r0, int c0, int r1, int c1) {
      faces.push_back({top(r0, c0), top(r1, c1), base(r1, c1)});
      faces.push_back({top(r0, c0), base(r1, c1), base(r0, c0)});
    };
    for (int r = 0; r + 1 < nr; ++r) side(r, 0, r + 1, 0), side(r, nc - 1, r + 1, nc - 1);
    for (int c = 0; c + 1 < nc; ++c) side(0, c, 0, c + 1), side(nr - 1, c, nr - 1, c + 1);
    return std::make_shared<const TriangleMesh>(std::move(vertices), std::move(faces), label);
  });
}

std::shared_ptr<const TriangleMesh> rectangle_mesh(double hx, double hy, const std::string& label) {
  Hash64 key;
  key.add("plane", 5);
  key.add(&hx, sizeof hx);
  key.add(&hy, sizeof hy);
  return cached_mesh(key.h, [&] {
    std::vector<Eigen::Vector3d> v = {{-hx, -hy, 0}, {hx, -hy, 0}, {hx, hy, 0}, {-hx, hy, 0}};
    return std::make_shared<const TriangleMesh>(std::move(v), std::vector<TriangleMesh::Face>{{0, 1, 2}, {0, 2, 3}},
                                                label);
  });
}

}  // namespace stvl::truth

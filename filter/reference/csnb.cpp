#include "filter/reference/csnb.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace stvl::filter::reference {

namespace {

bool finite(float x, float y, float z) { return std::isfinite(x) && std::isfinite(y) && std::isfinite(z); }

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

struct Point {
  float xyz[3];
  std::uint32_t index;  // column in the input
  std::array<int, 3> cube;
};

}  // namespace

std::array<int, 3> CsnbGrid::cube(float x, float y, float z) const {
  const float v[3] = {x, y, z};
  const double top = double((1 << grid_exponent) - 1);
  std::array<int, 3> c;
  for (int a = 0; a < 3; ++a) c[a] = int(std::clamp(std::floor((double(v[a]) - min_m[a]) / cube_edge_m), 0.0, top));
  return c;
}

bool CsnbGrid::neighbours(const float* a, const std::array<int, 3>& cube_a, const float* b,
                          const std::array<int, 3>& cube_b) const {
  for (int k = 0; k < 3; ++k) {
    if (std::abs(cube_a[k] - cube_b[k]) > reach) return false;
  }
  const float dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return (dx * dx + dy * dy) + dz * dz < radius_sq;
}

CsnbGrid csnb_grid(const Eigen::Matrix3Xf& points, const CsnbConfig& config) {
  float lo[3], hi[3];
  std::fill(lo, lo + 3, std::numeric_limits<float>::infinity());
  std::fill(hi, hi + 3, -std::numeric_limits<float>::infinity());
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    if (!finite(points(0, i), points(1, i), points(2, i))) continue;
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], points(a, i));
      hi[a] = std::max(hi[a], points(a, i));
    }
  }
  CsnbGrid grid;
  for (int a = 0; a < 3; ++a) {
    grid.min_m[a] = lo[a];
    grid.extent_m = std::max(grid.extent_m, double(hi[a]) - double(lo[a]));
  }
  const double d = config.voxel_size_m;
  if (config.grid_exponent == 0) {
    grid.cube_edge_m = std::max(d, grid.extent_m / 512.0);
    const double log = std::ceil(std::log2(std::max(grid.extent_m / grid.cube_edge_m, 1.0)));
    grid.grid_exponent = std::clamp(static_cast<int>(log), 4, 9);
  } else {
    grid.grid_exponent = config.grid_exponent;
    grid.cube_edge_m = grid.extent_m > 0.0 ? grid.extent_m / double(1 << grid.grid_exponent) : d;
  }
  grid.reach = int(std::clamp(std::ceil(d / grid.cube_edge_m), 1.0, double((1 << grid.grid_exponent) - 1)));
  grid.radius_sq = static_cast<float>(d * d);
  return grid;
}

Eigen::Matrix3Xf csnb(const Eigen::Matrix3Xf& points, const CsnbConfig& config) {
  std::vector<Point> p;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const float x = points(0, i), y = points(1, i), z = points(2, i);
    if (finite(x, y, z)) p.push_back({{x, y, z}, std::uint32_t(i), {}});
  }
  if (p.empty()) return Eigen::Matrix3Xf(3, 0);
  const CsnbGrid grid = csnb_grid(points, config);
  for (Point& q : p) q.cube = grid.cube(q.xyz[0], q.xyz[1], q.xyz[2]);
  // (cube, index) order, cubes by (z, y, x); the points are in index order already.
  auto cube_order = [](const Point& q) { return std::array<int, 3>{q.cube[2], q.cube[1], q.cube[0]}; };
  std::stable_sort(p.begin(), p.end(), [&](const Point& a, const Point& b) { return cube_order(a) < cube_order(b); });
  const std::size_t m = p.size();

  // Anchors: per cube the point nearest its centre (double), the first of equals.
  std::vector<char> anchor(m, 0);
  for (std::size_t b = 0; b < m;) {
    std::size_t e = b, best = b;
    double best_d = std::numeric_limits<double>::infinity();
    for (; e < m && p[e].cube == p[b].cube; ++e) {
      double d[3];
      for (int a = 0; a < 3; ++a) {
        d[a] = double(p[e].xyz[a]) - (grid.min_m[a] + (double(p[e].cube[a]) + 0.5) * grid.cube_edge_m);
      }
      const double d2 = (d[0] * d[0] + d[1] * d[1]) + d[2] * d[2];
      if (d2 < best_d) {
        best_d = d2;
        best = e;
      }
    }
    anchor[best] = 1;
    b = e;
  }

  // Every pair, once.
  std::vector<std::vector<std::uint32_t>> near(m);
  for (std::size_t s = 0; s < m; ++s) {
    for (std::size_t t = s + 1; t < m; ++t) {
      if (grid.neighbours(p[s].xyz, p[s].cube, p[t].xyz, p[t].cube)) {
        near[s].push_back(std::uint32_t(t));
        near[t].push_back(std::uint32_t(s));
      }
    }
  }

  // The random order of the non-anchor points: (high 32 bits of the hash of the point's index, position).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> order;
  const std::uint64_t seeded = splitmix64(splitmix64(config.seed) ^ 0x43534E42ull);
  for (std::size_t s = 0; s < m; ++s) {
    if (!anchor[s]) order.push_back({std::uint32_t(splitmix64(seeded ^ p[s].index) >> 32), std::uint32_t(s)});
  }
  std::sort(order.begin(), order.end());

  std::vector<char> live(m, 1);
  auto live_neighbours = [&](std::size_t s) {
    int k = 0;
    for (const std::uint32_t t : near[s]) k += live[t];
    return k;
  };
  const std::size_t K = static_cast<std::size_t>(config.batch_size);
  for (;;) {
    std::vector<std::uint32_t> marked;  // in the random order
    for (const auto& [priority, s] : order) {
      if (live[s] && live_neighbours(s) > config.max_neighbours) marked.push_back(s);
    }
    const bool more = marked.size() > K;
    if (more) marked.resize(K);
    for (const std::uint32_t s : marked) live[s] = 0;
    if (!more) break;
  }

  // Anchors over the bound, all judged on the same live set, delete their non-anchor neighbours.
  std::vector<std::uint32_t> claims;
  for (std::size_t s = 0; s < m; ++s) {
    if (anchor[s] && live_neighbours(s) > config.max_neighbours) claims.push_back(std::uint32_t(s));
  }
  for (const std::uint32_t a : claims) {
    for (const std::uint32_t t : near[a]) {
      if (!anchor[t]) live[t] = 0;
    }
  }

  Eigen::Matrix3Xf out(3, std::count(live.begin(), live.end(), 1));
  Eigen::Index o = 0;
  for (std::size_t s = 0; s < m; ++s) {
    if (live[s]) out.col(o++) << p[s].xyz[0], p[s].xyz[1], p[s].xyz[2];
  }
  return out;
}

}  // namespace stvl::filter::reference

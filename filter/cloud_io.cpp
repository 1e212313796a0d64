#include "filter/cloud_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <vector>

#include "filter/detail/shared.hpp"

namespace stvl::filter {

namespace {
constexpr char kMagic[8] = {'S', 'T', 'V', 'L', 'C', 'L', 'D', '1'};
}

void save_cloud(const std::string& path, const Eigen::Matrix3Xf& points) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error("save_cloud: cannot open '" + path + "' for writing");
  const std::uint64_t count = static_cast<std::uint64_t>(points.cols());
  out.write(kMagic, sizeof(kMagic));
  out.write(reinterpret_cast<const char*>(&count), sizeof(count));
  out.write(reinterpret_cast<const char*>(points.data()), static_cast<std::streamsize>(count * 3 * sizeof(float)));
  if (!out) throw std::runtime_error("save_cloud: writing '" + path + "' failed");
}

Eigen::Matrix3Xf load_cloud(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw std::runtime_error("load_cloud: cannot open '" + path + "'");
  const std::uint64_t size = static_cast<std::uint64_t>(in.tellg());
  in.seekg(0);
  char magic[8] = {};
  std::uint64_t count = 0;
  if (size < 16 || !in.read(magic, 8) || std::memcmp(magic, kMagic, 8) != 0) {
    throw std::invalid_argument("load_cloud: '" + path + "' is not a cloud file (no STVLCLD1 header)");
  }
  in.read(reinterpret_cast<char*>(&count), sizeof(count));
  if (count > (size - 16) / 12 || 16 + count * 12 != size) {
    throw std::invalid_argument("load_cloud: '" + path + "' declares " + std::to_string(count) +
                                " points but holds " + std::to_string(size) + " bytes (expected 16 + 12 * count)");
  }
  if (count >= std::numeric_limits<std::uint32_t>::max()) {
    throw std::invalid_argument("load_cloud: '" + path + "' has too many points: " + std::to_string(count));
  }
  Eigen::Matrix3Xf points(3, static_cast<Eigen::Index>(count));
  in.read(reinterpret_cast<char*>(points.data()), static_cast<std::streamsize>(count * 12));
  if (!in) throw std::runtime_error("load_cloud: reading '" + path + "' failed");
  return points;
}

Eigen::Matrix3Xf make_corridor_cloud(std::uint64_t seed, int width_px, int height_px) {
  if (width_px <= 0 || height_px <= 0 || width_px > 8192 || height_px > 8192) {
    throw std::invalid_argument("make_corridor_cloud: image size must be 1..8192 px, got " + std::to_string(width_px) +
                                "x" + std::to_string(height_px));
  }
  struct Box {
    Eigen::Vector3d lo, hi;
  };
  const Box boxes[] = {{{-1.0, 2.0, 0.0}, {-0.5, 2.6, 0.8}},
                       {{0.4, 4.0, 0.0}, {1.0, 4.5, 1.2}},
                       {{-0.3, 6.5, 0.0}, {0.3, 7.0, 0.4}},
                       {{-1.0, 8.0, 1.5}, {-0.7, 9.0, 2.5}}};
  const double focal = width_px / 2.0 / std::tan(87.0 / 2.0 * M_PI / 180.0);
  const double cx = (width_px - 1) / 2.0, cy = (height_px - 1) / 2.0;
  const Eigen::Vector3d origin(0.1, 0.0, 1.0);
  const double pitch = 0.12;  // looking slightly down
  std::vector<float> xyz;
  xyz.reserve(static_cast<std::size_t>(width_px) * height_px * 3);
  for (int v = 0; v < height_px; ++v) {
    for (int u = 0; u < width_px; ++u) {
      // Optical ray (x right, y down, z forward) to world (x right, y forward, z up), pitched.
      const double rx = (u - cx) / focal, ry = (v - cy) / focal;
      Eigen::Vector3d dir(rx, std::cos(pitch) - ry * std::sin(pitch), -ry * std::cos(pitch) - std::sin(pitch));
      double t = std::numeric_limits<double>::infinity();
      auto plane = [&](int axis, double value) {
        if (dir[axis] == 0.0) return;
        const double s = (value - origin[axis]) / dir[axis];
        if (s > 0.0) t = std::min(t, s);
      };
      plane(0, -1.0);
      plane(0, 1.0);
      plane(2, 0.0);
      plane(2, 2.5);
      plane(1, 20.0);
      for (const Box& b : boxes) {
        double t0 = 0.0, t1 = t;
        for (int a = 0; a < 3 && t0 <= t1; ++a) {
          if (dir[a] == 0.0) {
            if (origin[a] < b.lo[a] || origin[a] > b.hi[a]) t1 = -1.0;
            continue;
          }
          double s0 = (b.lo[a] - origin[a]) / dir[a], s1 = (b.hi[a] - origin[a]) / dir[a];
          if (s0 > s1) std::swap(s0, s1);
          t0 = std::max(t0, s0);
          t1 = std::min(t1, s1);
        }
        if (t0 <= t1 && t0 > 0.0) t = t0;
      }
      const double depth = t;  // the ray's forward component is 1, so t is the optical depth
      if (!(depth > 0.2 && depth < 10.0)) continue;
      const std::uint64_t counter = static_cast<std::uint64_t>(v) * width_px + u;
      const double u1 = (double(detail::hash3(seed, counter, 1) >> 11) + 0.5) * 0x1.0p-53;
      const double u2 = double(detail::hash3(seed, counter, 2) >> 11) * 0x1.0p-53;
      const double gauss = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
      const double noisy = depth + 0.001 * depth * depth * gauss;
      const Eigen::Vector3d p = origin + dir * noisy;
      xyz.insert(xyz.end(), {float(p.x()), float(p.y()), float(p.z())});
    }
  }
  return Eigen::Map<const Eigen::Matrix3Xf>(xyz.data(), 3, static_cast<Eigen::Index>(xyz.size() / 3));
}

}  // namespace stvl::filter

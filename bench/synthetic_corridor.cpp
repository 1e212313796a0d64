#include "bench/synthetic_corridor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "common/splitmix.hpp"

namespace stvl::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kHalfWidth = 1.0;
constexpr double kCeiling = 2.5;
constexpr double kEndWall = 30.0;

// Counter-based generator (splitmix64 chained over the inputs): the same (seed, a, b) gives the same value
// anywhere. The same construction as filter's detail::hash3, kept here so that bench/ uses no filter internals.
std::uint64_t hash3(std::uint64_t seed, std::uint64_t a, std::uint64_t b) {
  return splitmix64(splitmix64(splitmix64(seed) ^ a) ^ b);
}
// Uniform in (0, 1] (stream `b` of counter `a`) and in [0, 1).
double uniform_open0(std::uint64_t seed, std::uint64_t a, std::uint64_t b) {
  return (double(hash3(seed, a, b) >> 11) + 0.5) * 0x1.0p-53;
}
double uniform(std::uint64_t seed, std::uint64_t a, std::uint64_t b) {
  return double(hash3(seed, a, b) >> 11) * 0x1.0p-53;
}

// Slab test; the entry distance, or infinity when the ray misses the box or starts inside it.
double ray_box(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const CorridorBox& b) {
  double t0 = 0.0, t1 = kInfinity;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) {
      if (o[a] < b.lo_m[a] || o[a] > b.hi_m[a]) return kInfinity;
      continue;
    }
    double s0 = (b.lo_m[a] - o[a]) / d[a], s1 = (b.hi_m[a] - o[a]) / d[a];
    if (s0 > s1) std::swap(s0, s1);
    t0 = std::max(t0, s0);
    t1 = std::min(t1, s1);
  }
  return t0 <= t1 && t0 > 0.0 ? t0 : kInfinity;
}

double cast_ray(const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  double t = kInfinity;
  auto plane = [&](int axis, double value) {
    if (d[axis] == 0.0) return;
    const double s = (value - o[axis]) / d[axis];
    if (s > 0.0) t = std::min(t, s);
  };
  plane(0, -kHalfWidth);
  plane(0, kHalfWidth);
  plane(2, 0.0);
  plane(2, kCeiling);
  plane(1, kEndWall);
  for (const CorridorBox& b : kCorridorBoxes) t = std::min(t, ray_box(o, d, b));
  return t;
}

// Casts every pixel; calls sink(p_W) (double precision) for each one in range, in row order.
template <class Sink>
void cast_points(const SyntheticCamera& camera, const Eigen::Isometry3d& T_world_camera, std::uint64_t seed,
                 std::uint64_t frame, Sink&& sink) {
  const int width = camera.width_px, height = camera.height_px;
  const Eigen::Vector3d o = T_world_camera.translation();
  const Eigen::Matrix3d R = T_world_camera.linear();
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const Eigen::Vector3d ray_C((u - camera.cx_px) / camera.fx_px, (v - camera.cy_px) / camera.fy_px, 1.0);
      const Eigen::Vector3d d_W = R * ray_C;
      const double depth = cast_ray(o, d_W);  // ray_C.z = 1, so t is the depth along the optical axis
      if (!(depth > camera.min_range_m && depth < camera.max_range_m)) continue;
      const std::uint64_t counter =
          (frame * height + static_cast<std::uint64_t>(v)) * width + static_cast<std::uint64_t>(u);
      const double u1 = uniform_open0(seed, counter, 1), u2 = uniform(seed, counter, 2);
      const double gauss = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
      sink(Eigen::Vector3d(o + d_W * (depth + camera.noise_per_m * depth * depth * gauss)));
    }
  }
}

// Centroid per voxel of voxel_size_m, in key order.
Eigen::Matrix3Xf voxel_centroids(const std::vector<Eigen::Vector3d>& points, double voxel_size_m) {
  std::vector<std::pair<Eigen::Vector3i, Eigen::Vector3d>> keyed;
  keyed.reserve(points.size());
  for (const auto& p : points) keyed.emplace_back((p / voxel_size_m).array().floor().cast<int>(), p);
  auto less = [](const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  };
  std::sort(keyed.begin(), keyed.end(), [&](const auto& a, const auto& b) { return less(a.first, b.first); });
  std::vector<Eigen::Vector3f> out;
  for (std::size_t i = 0; i < keyed.size();) {
    std::size_t j = i;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (; j < keyed.size() && keyed[j].first == keyed[i].first; ++j) sum += keyed[j].second;
    out.push_back((sum / static_cast<double>(j - i)).cast<float>());
    i = j;
  }
  Eigen::Matrix3Xf cloud(3, static_cast<Eigen::Index>(out.size()));
  for (std::size_t i = 0; i < out.size(); ++i) cloud.col(static_cast<Eigen::Index>(i)) = out[i];
  return cloud;
}

}  // namespace

double cast_corridor_ray(const Eigen::Vector3d& origin_W, const Eigen::Vector3d& direction_W) {
  return cast_ray(origin_W, direction_W);
}

SyntheticCamera SyntheticCamera::from_fov(int width_px, int height_px, double horizontal_fov_rad,
                                          double vertical_fov_rad) {
  if (width_px <= 0 || height_px <= 0 || width_px > 8192 || height_px > 8192) {
    throw std::invalid_argument("synthetic camera: image size must be 1..8192 px, got " + std::to_string(width_px) +
                                "x" + std::to_string(height_px));
  }
  SyntheticCamera camera;
  camera.width_px = width_px;
  camera.height_px = height_px;
  camera.fx_px = width_px / 2.0 / std::tan(horizontal_fov_rad / 2.0);
  camera.fy_px = vertical_fov_rad > 0.0 ? height_px / 2.0 / std::tan(vertical_fov_rad / 2.0) : camera.fx_px;
  camera.cx_px = (width_px - 1) / 2.0;
  camera.cy_px = (height_px - 1) / 2.0;
  return camera;
}

Eigen::Matrix3Xf cast_corridor_cloud(const SyntheticCamera& camera, const Eigen::Isometry3d& T_world_camera,
                                     std::uint64_t seed, std::uint64_t frame) {
  std::vector<float> xyz;
  xyz.reserve(static_cast<std::size_t>(camera.width_px) * camera.height_px * 3);
  cast_points(camera, T_world_camera, seed, frame, [&](const Eigen::Vector3d& p) {
    xyz.insert(xyz.end(), {float(p.x()), float(p.y()), float(p.z())});
  });
  return Eigen::Map<const Eigen::Matrix3Xf>(xyz.data(), 3, static_cast<Eigen::Index>(xyz.size() / 3));
}

Eigen::Matrix3Xf make_corridor_cloud(std::uint64_t seed, int width_px, int height_px) {
  const SyntheticCamera camera = SyntheticCamera::from_fov(width_px, height_px, 87.0 * kPi / 180.0);
  const double pitch = 0.12;  // looking slightly down
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  // Columns: the optical x (right), y (down) and z (forward) axes in the world.
  T_world_camera.linear() << 1.0, 0.0, 0.0,    //
      0.0, -std::sin(pitch), std::cos(pitch),  //
      0.0, -std::cos(pitch), -std::sin(pitch);
  T_world_camera.translation() = Eigen::Vector3d(0.1, 0.0, 1.0);
  return cast_corridor_cloud(camera, T_world_camera, seed);
}

SyntheticFrame synthetic_corridor_frame(std::uint64_t seed, int frame, double voxel_size_m) {
  if (!(voxel_size_m > 0.0)) throw std::invalid_argument("synthetic_corridor_frame: voxel_size_m must be > 0");
  constexpr double kFrameRate = 30.0;
  SyntheticCamera camera = SyntheticCamera::from_fov(424, 240, kFrameHorizontalFovRad, kFrameVerticalFovRad);
  camera.min_range_m = kFrameMinRangeM;
  camera.max_range_m = kFrameMaxRangeM;
  // Pose jitter in [-1, 1) from streams 3 and 4 of counter `frame` (the pixels' noise uses streams 1 and 2).
  const auto jitter = [&](std::uint64_t stream) { return 2.0 * uniform(seed, std::uint64_t(frame), stream) - 1.0; };
  SyntheticFrame out;
  out.time_s = 1.0 + frame / kFrameRate;
  const double yaw = kPi / 2 + 0.15 * std::sin(0.05 * frame) + 0.01 * jitter(3);  // heading +y, swaying
  Eigen::Matrix3d R_base_optical;  // optical axes in the base frame: z forward (+x), x right (-y), y down (-z)
  R_base_optical << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  out.T_world_camera.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_base_optical;
  out.T_world_camera.translation() = Eigen::Vector3d(0.05 * jitter(4), 0.03 * frame, 0.5);
  std::vector<Eigen::Vector3d> points;
  points.reserve(static_cast<std::size_t>(camera.width_px) * camera.height_px);
  cast_points(camera, out.T_world_camera, seed, std::uint64_t(frame),
              [&](const Eigen::Vector3d& p) { points.push_back(p); });
  out.points_W = voxel_centroids(points, voxel_size_m);
  return out;
}

}  // namespace stvl::bench

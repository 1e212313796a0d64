#pragma once
// The synthetic corridor the benchmarks (and the tests of filter/ and mapping/) draw their clouds from: one
// analytic scene and a pinhole ray caster, Eigen only, so it builds with filter/ alone.
//
// Scene (world frame, z up, the corridor along +y, x to its right): walls at x = -1 m and x = +1 m, floor z = 0,
// ceiling z = 2.5 m, an end wall at y = 30 m, three boxes standing on the floor and one hanging from the
// ceiling (kCorridorBoxes).
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>

namespace stvl::bench {

struct CorridorBox {
  Eigen::Vector3d lo_m, hi_m;  // opposite corners, world frame
};

inline const CorridorBox kCorridorBoxes[] = {
    {{-1.0, 2.0, 0.0}, {-0.5, 2.6, 0.8}},  // on the floor against the left wall
    {{0.4, 4.0, 0.0}, {1.0, 4.5, 1.2}},    // against the right wall
    {{-0.3, 6.5, 0.0}, {0.3, 7.0, 0.4}},   // low, mid corridor
    {{-1.0, 8.0, 1.5}, {-0.7, 9.0, 2.5}},  // hanging from the ceiling at the left wall
};

// First hit of the ray origin_W + t * direction_W (direction of any non-zero length) with the corridor: the
// smallest t > 0, or +infinity when the ray hits nothing (it always does from inside the corridor).
double cast_corridor_ray(const Eigen::Vector3d& origin_W, const Eigen::Vector3d& direction_W);

// Pinhole depth camera: pixel (u, v) (u right, v down, integers at pixel centres) looks along
// ((u - cx) / fx, (v - cy) / fy, 1) in the optical frame (x right, y down, z forward).
struct SyntheticCamera {
  int width_px = 848;
  int height_px = 480;
  double fx_px = 0.0, fy_px = 0.0, cx_px = 0.0, cy_px = 0.0;
  double min_range_m = 0.2;  // a pixel is kept when min_range_m < depth < max_range_m (depth along z)
  double max_range_m = 10.0;
  double noise_per_m = 0.001;  // depth noise: Gaussian, sigma = noise_per_m * depth^2

  // fx from the horizontal FOV, fy from the vertical one (fy = fx when vertical_fov_rad is 0: square pixels),
  // principal point at the image centre. Throws std::invalid_argument for a size outside 1..8192 px.
  static SyntheticCamera from_fov(int width_px, int height_px, double horizontal_fov_rad,
                                  double vertical_fov_rad = 0.0);
};

// One camera frame of the corridor in the world frame: a point per pixel whose depth lies in the camera's
// range, the depth noise drawn from a counter-based generator of (seed, frame * width * height + pixel), so the
// same arguments give the same cloud on any machine. Points in row order (v, then u).
Eigen::Matrix3Xf cast_corridor_cloud(const SyntheticCamera& camera, const Eigen::Isometry3d& T_world_camera,
                                     std::uint64_t seed, std::uint64_t frame = 0);

// The filter benchmark's cloud: a width x height camera with square pixels and an 87 deg horizontal FOV (848x480
// is D435-like) at (0.1, 0, 1.0) m looking down the corridor, pitched 0.12 rad down, range 0.2..10 m. About
// 400k points at 848x480.
Eigen::Matrix3Xf make_corridor_cloud(std::uint64_t seed = 1, int width_px = 848, int height_px = 480);

// The map benchmark's frames: a 424x240 camera (kFrame*: 87 x 58 deg, range 0.2..5 m) at 0.5 m height,
// 30 frames/s, driving down the corridor (from y = 0) at 0.9 m/s and swaying in yaw, with small pose jitter;
// the cloud is voxel-filtered (centroid per voxel of voxel_size_m). Deterministic in (seed, frame).
inline constexpr double kFrameHorizontalFovRad = 87.0 * 3.14159265358979323846 / 180.0;
inline constexpr double kFrameVerticalFovRad = 58.0 * 3.14159265358979323846 / 180.0;
inline constexpr double kFrameMinRangeM = 0.2;
inline constexpr double kFrameMaxRangeM = 5.0;
struct SyntheticFrame {
  Eigen::Matrix3Xf points_W;
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();  // optical frame
  double time_s = 0.0;
};
SyntheticFrame synthetic_corridor_frame(std::uint64_t seed, int frame, double voxel_size_m);

}  // namespace stvl::bench

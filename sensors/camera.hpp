#pragma once
// Pinhole intrinsics of a depth camera, in the optical frame C (z forward, x right, y down).
// Pixel (u, v) has its centre at integer coordinates (OpenCV convention): u = fx * x / z + cx.
#include <Eigen/Core>

#include <optional>

namespace stvl::sensors {

struct CameraIntrinsics {
  int width = 848;
  int height = 480;
  double fx = 433.0;  // px
  double fy = 433.0;  // px
  double cx = 423.5;  // px
  double cy = 239.5;  // px
  double min_range_m = 0.28;
  double max_range_m = 10.0;
  double rate_hz = 30.0;

  // RealSense D435 depth stream, nominal 87 x 58 deg. The renderer draws square pixels. 848x480 keeps the vertical
  // 58 deg (fx = fy = 433.0 px at 480 rows; 88.8 deg horizontally, spec 87 +- 3). 640x480 is the real stream's
  // geometry from a D435's camera_info (../shared/realdata): fx = fy = 390.43 px, cx 331.39, cy 242.19
  // (78.7 x 63.2 deg, principal point off centre).
  static CameraIntrinsics d435_848x480();
  static CameraIntrinsics d435_640x480();
  // Square pixels from a horizontal FOV, principal point at the image centre.
  static CameraIntrinsics from_hfov(int width, int height, double hfov_rad, double min_range_m, double max_range_m,
                                    double rate_hz);

  // Throws std::invalid_argument naming the first bad field: sizes > 0, focal lengths finite and > 0,
  // principal point finite, FOV < 180 deg, 0 < min_range_m < max_range_m finite, rate_hz finite and > 0.
  void validate() const;
  bool square_pixels() const;  // |fx - fy| <= 1e-9 * fy

  // Full angles of the frustum through the outer pixel edges (accounts for an off-centre principal point).
  double hfov_rad() const;
  double vfov_rad() const;
};

// Ray through continuous pixel coordinates (u, v), scaled to z = 1 (so a point on it at depth z is z * ray).
Eigen::Vector3d pixel_ray_C(const CameraIntrinsics& intrinsics, double u, double v);
// Continuous pixel coordinates of a point in the optical frame; empty when z <= 0.
std::optional<Eigen::Vector2d> project_to_pixel(const CameraIntrinsics& intrinsics, const Eigen::Vector3d& p_C);

}  // namespace stvl::sensors

#include "sensors/camera.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "common/units.hpp"

namespace stvl::sensors {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kD435VfovRad = 58.0 * kPi / 180.0;

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("CameraIntrinsics: " + message);
}

std::string str(double value) { return std::to_string(value); }

CameraIntrinsics d435(int width) {
  CameraIntrinsics k;
  k.width = width;
  k.height = 480;
  k.fy = 0.5 * k.height / std::tan(0.5 * kD435VfovRad);
  k.fx = k.fy;
  k.cx = 0.5 * k.width - 0.5;
  k.cy = 0.5 * k.height - 0.5;
  return k;
}

}  // namespace

CameraIntrinsics CameraIntrinsics::d435_848x480() { return d435(848); }
// The real D435's 640x480 depth stream is not a crop of 848x480 but a wider, scaled mode: the camera_info of the
// D435 recording in ../shared/realdata (d435_office_corner/single_depth_color_640x480.bag, librealsense, firmware
// 05.09.14.00) gives fx = fy = 390.43 px, cx 331.39, cy 242.19 (78.7 x 63.2 deg). The principal point is off
// centre; the renderer draws it so (frustum_center/top/bottom).
CameraIntrinsics CameraIntrinsics::d435_640x480() {
  CameraIntrinsics k = d435(640);
  k.fx = k.fy = 390.43;
  k.cx = 331.39;
  k.cy = 242.19;
  return k;
}

CameraIntrinsics CameraIntrinsics::from_hfov(int width, int height, double hfov_rad, double min_range_m,
                                             double max_range_m, double rate_hz) {
  require(std::isfinite(hfov_rad) && hfov_rad > 0.0 && hfov_rad < kPi,
          "hfov_rad " + str(hfov_rad) + " must be in (0, pi)");
  CameraIntrinsics k;
  k.width = width;
  k.height = height;
  k.fx = k.fy = 0.5 * width / std::tan(0.5 * hfov_rad);
  k.cx = 0.5 * width - 0.5;
  k.cy = 0.5 * height - 0.5;
  k.min_range_m = min_range_m;
  k.max_range_m = max_range_m;
  k.rate_hz = rate_hz;
  k.validate();
  return k;
}

void CameraIntrinsics::validate() const {
  require(width > 0, "width " + std::to_string(width) + " must be > 0");
  require(height > 0, "height " + std::to_string(height) + " must be > 0");
  require(width <= 16384 && height <= 16384,
          "image " + std::to_string(width) + "x" + std::to_string(height) + " larger than 16384");
  require(std::isfinite(fx) && fx > 0.0, "fx " + str(fx) + " must be finite and > 0");
  require(std::isfinite(fy) && fy > 0.0, "fy " + str(fy) + " must be finite and > 0");
  require(std::isfinite(cx), "cx " + str(cx) + " must be finite");
  require(std::isfinite(cy), "cy " + str(cy) + " must be finite");
  // The frustum through the outer pixel edges must stay within 180 deg on both sides of the optical axis.
  require(-0.5 - cx < 0.0 && width - 0.5 - cx > 0.0,
          "cx " + str(cx) + " puts the optical axis outside the image (width " + std::to_string(width) + ")");
  require(-0.5 - cy < 0.0 && height - 0.5 - cy > 0.0,
          "cy " + str(cy) + " puts the optical axis outside the image (height " + std::to_string(height) + ")");
  require(std::isfinite(hfov_rad()) && hfov_rad() < kPi, "horizontal FOV must be < 180 deg");
  require(std::isfinite(vfov_rad()) && vfov_rad() < kPi, "vertical FOV must be < 180 deg");
  require(std::isfinite(min_range_m) && min_range_m > 0.0, "min_range_m " + str(min_range_m) + " must be > 0");
  require(std::isfinite(max_range_m) && max_range_m > min_range_m,
          "max_range_m " + str(max_range_m) + " must be finite and > min_range_m " + str(min_range_m));
  require(std::isfinite(rate_hz) && rate_hz > 0.0, "rate_hz " + str(rate_hz) + " must be finite and > 0");
}

bool CameraIntrinsics::square_pixels() const { return std::abs(fx - fy) <= kRelativeEpsilon * std::abs(fy); }

double CameraIntrinsics::hfov_rad() const { return std::atan((cx + 0.5) / fx) + std::atan((width - 0.5 - cx) / fx); }

double CameraIntrinsics::vfov_rad() const { return std::atan((cy + 0.5) / fy) + std::atan((height - 0.5 - cy) / fy); }

Eigen::Vector3d pixel_ray_C(const CameraIntrinsics& intrinsics, double u, double v) {
  return {(u - intrinsics.cx) / intrinsics.fx, (v - intrinsics.cy) / intrinsics.fy, 1.0};
}

std::optional<Eigen::Vector2d> project_to_pixel(const CameraIntrinsics& intrinsics, const Eigen::Vector3d& p_C) {
  if (!(p_C.z() > 0.0)) return std::nullopt;
  return Eigen::Vector2d(intrinsics.fx * p_C.x() / p_C.z() + intrinsics.cx,
                         intrinsics.fy * p_C.y() / p_C.z() + intrinsics.cy);
}

}  // namespace stvl::sensors

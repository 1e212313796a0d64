#pragma once
// Metric depth images (row-major, top row first; 0 = invalid) and their conversion to clouds and PNG files.
#include "sensors/camera.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <string>
#include <vector>

namespace stvl::sensors {

struct DepthImage {
  int width = 0;
  int height = 0;
  std::vector<float> depth_m;  // along the optical axis (z), width * height values, 0 = invalid

  DepthImage() = default;
  DepthImage(int width_px, int height_px) : width(width_px), height(height_px), depth_m(size_t(width_px) * height_px) {}
  float at(int u, int v) const { return depth_m[size_t(v) * width + u]; }
  float& at(int u, int v) { return depth_m[size_t(v) * width + u]; }
  int valid_count() const;
};

// Points in the optical frame C, one column per valid pixel, in row-major pixel order.
// Throws std::invalid_argument when the image size does not match the intrinsics.
Eigen::Matrix3Xf depth_to_cloud(const DepthImage& image, const CameraIntrinsics& intrinsics);
// Allocation-free variant for the frame loop: points_C keeps width * height columns (resized only when smaller);
// the first `return value` columns are the points.
Eigen::Index depth_to_cloud(const DepthImage& image, const CameraIntrinsics& intrinsics, Eigen::Matrix3Xf& points_C);
// The same, and the points in the world frame too: points_W (exactly the points' columns) = T_world_camera *
// points_C in float, rounded as Eigen's (R * points_C).colwise() + t (common/transform_points.hpp), each block of
// rows moved while it is still in cache.
Eigen::Index depth_to_cloud(const DepthImage& image, const CameraIntrinsics& intrinsics, Eigen::Matrix3Xf& points_C,
                            const Eigen::Isometry3d& T_world_camera, Eigen::Matrix3Xf& points_W);

// Depth in millimetres as realsense2_camera publishes it (16UC1): rounded, saturated at 65535, 0 = invalid.
std::vector<std::uint16_t> depth_to_millimetres(const DepthImage& image);
// 16-bit grey PNG in millimetres (rounded, saturated at 65535; 0 = invalid), as realsense2_camera publishes.
// Written to "<path>.tmp" then renamed. Throws std::runtime_error naming the path on I/O failure.
void write_depth_png_mm(const DepthImage& image, const std::string& path);
// 8-bit RGB PNG for people: turbo-like colormap over [min_m, max_m] (near = blue, far = red), invalid black.
void write_depth_png_colorized(const DepthImage& image, const std::string& path, double min_m, double max_m);
// Reads a 16-bit millimetre PNG written by write_depth_png_mm (for tests and tools).
DepthImage read_depth_png_mm(const std::string& path);

}  // namespace stvl::sensors

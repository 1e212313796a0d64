#pragma once
// Shared by the readers behind recording.hpp (not part of the interface).
#include <Eigen/Geometry>

#include <memory>
#include <string>
#include <vector>

#include "recording/bag_writer.hpp"
#include "recording/recording.hpp"

namespace stvl::recording::detail {

std::unique_ptr<Recording> open_bag(const std::string& path, const RecordingOptions& options);
std::unique_ptr<Recording> open_png_folder(const std::string& path, const RecordingOptions& options);
// rosbag2: a folder with metadata.yaml, a bare .mcap or a .db3 (ros2_reader.cpp).
std::unique_ptr<Recording> open_ros2(const std::string& path, const RecordingOptions& options);
// What a ROS 1 bag (bag_reader.cpp) or rosbag2 storage (ros2_reader.cpp) holds.
RecordingContents list_bag(const std::string& path);
RecordingContents list_ros2(const std::string& path);
// A rosbag2 folder with one MCAP file, written as folder.active until close() (ros2_bag_writer.cpp).
std::unique_ptr<BagSink> make_ros2_bag_writer(const std::string& folder, BagCompression compression);

// The candidate closest to `name` (edit distance); empty when there are none.
std::string nearest_name(const std::string& name, const std::vector<std::string>& candidates);

// Rotation from a quaternion (w, x, y, z) and a translation; throws std::invalid_argument("<what>: ...") when a
// value is not finite or the rotation is not orthonormal within 1e-3 (a quaternion whose norm is not 1).
Eigen::Isometry3d rigid_from_quaternion(double tx, double ty, double tz, double qx, double qy, double qz, double qw,
                                        const std::string& what);
// The same check for a rotation matrix (det +1 too).
Eigen::Isometry3d rigid_from_matrix(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const std::string& what);

// Intrinsics with the options' range; throws std::invalid_argument("<what>: ...") for zero, negative or
// non-finite values.
sensors::CameraIntrinsics make_intrinsics(double width, double height, double fx, double fy, double cx, double cy,
                                          double rate_hz, const RecordingOptions& options, const std::string& what);

}  // namespace stvl::recording::detail

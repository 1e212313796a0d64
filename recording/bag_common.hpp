#pragma once
// What the ROS 1 and ROS 2 bag readers share (not part of the interface, no ROS headers): depth images to
// metres, and poses from /tf, /tf_static or odometry (the choice of source and the lookup per frame).
#include <Eigen/Geometry>

#include <cstdint>
#include <string>

#include "recording/recording.hpp"
#include "recording/tf_buffer.hpp"

namespace stvl::recording::detail {

struct ImageView {
  std::string encoding;
  std::uint32_t width = 0, height = 0, step = 0;
  bool is_bigendian = false;
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
};

// 2 for 16UC1 / mono16, 4 for 32FC1; throws std::invalid_argument("<where>: encoding ... is not depth").
int depth_bytes_per_pixel(const std::string& encoding, const std::string& where);
// The image in metres (16-bit x unit_m; 32FC1 NaN, Inf, <= 0 -> 0); throws std::invalid_argument("<at>: ...")
// for an empty image, a size that disagrees with k (named by info_topic), a short step or short data.
void decode_depth(const ImageView& image, const sensors::CameraIntrinsics& k, double unit_m, const std::string& at,
                  const std::string& info_topic, sensors::DepthImage& out);

// Poses of a recording: fill tf (add_transform) and odom, then resolve(); pose_at() per frame.
class PoseResolver {
 public:
  // One /tf or /tf_static edge; throws for a non-rigid transform or a frame with two parents.
  void add_transform(const std::string& path, const std::string& topic, bool is_static, const std::string& parent,
                     const std::string& child, double stamp_s, const double t[3], const double q[4]);
  // One odometry sample (frame and child from the first).
  void add_odometry(const std::string& path, const std::string& topic, double stamp_s, const std::string& frame,
                    const std::string& child, const double p[3], const double q[4]);
  // Chooses the source (odometry when options.odom_topic is set, /tf when it holds the camera or the robot,
  // else static) and sets info.fixed_frame and info.pose_source; throws for an impossible fixed frame.
  void resolve(RecordingInfo& info, const RecordingOptions& options);
  // The poses at t; throws std::invalid_argument("<where>: frame <index> ...: no pose at t ...").
  void pose_at(const RecordingInfo& info, const RecordingOptions& options, const std::string& where, double t,
               std::size_t index, Eigen::Isometry3d& T_fixed_camera, Eigen::Isometry3d& T_fixed_base) const;

 private:
  TfBuffer tf_;
  PoseSeries odom_;
  std::string odom_frame_, base_frame_;
  bool camera_from_options_ = false;  // /tf reaches base_frame_ but not the images' frame_id
  Eigen::Isometry3d T_base_camera_ = Eigen::Isometry3d::Identity();
};

std::string strip_slash(std::string frame);
std::string join(const std::vector<std::string>& names);

}  // namespace stvl::recording::detail

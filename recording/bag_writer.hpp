#pragma once
// A run's export: `BagSink`, what every format writes, with two implementations: `BagWriter`, a ROS 1 bag
// (format 2.0; rosbag behind the pimpl in bag_writer.cpp), and a rosbag2 folder with one MCAP file
// (make_bag_writer(path, BagFormat::kRos2, ...): ros2_bag_writer.cpp). No ROS, MCAP or compression headers here.
//
// Times are simulated seconds (t_s >= 0). rosbag refuses record times below ros::TIME_MIN (1 ns), and a zero
// header stamp means "latest" to tf, so every header stamp, record time and /clock value is
// t_s + kBagTimeOffset_s. Frames follow REP-105: map -> odom -> base_link -> camera_link ->
// camera_depth_optical_frame.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "mapping/costmap.hpp"
#include "sensors/camera.hpp"

namespace stvl::recording {

inline constexpr double kBagTimeOffset_s = 1.0;

inline constexpr const char* kMapFrame = "map";
inline constexpr const char* kOdomFrame = "odom";
inline constexpr const char* kBaseFrame = "base_link";
inline constexpr const char* kCameraLinkFrame = "camera_link";
inline constexpr const char* kCameraOpticalFrame = "camera_depth_optical_frame";
// A camera's frames and topics by its name: <camera>_link, <camera>_depth_optical_frame, /<camera>/<what>
// ("camera" gives the names above and /camera/depth/...).
inline std::string camera_link_frame(const std::string& camera) { return camera + "_link"; }
inline std::string camera_optical_frame(const std::string& camera) { return camera + "_depth_optical_frame"; }
inline std::string camera_topic(const std::string& camera, const std::string& what) {
  return "/" + camera + "/" + what;
}
// The topics nav2 (Jazzy) publishes its drive on: planner_server's path, the controller's velocity command and
// the two costmaps.
inline constexpr const char* kPlanTopic = "/plan";
inline constexpr const char* kCmdVelTopic = "/cmd_vel";
inline constexpr const char* kLocalCostmapTopic = "/local_costmap/costmap";
inline constexpr const char* kGlobalCostmapTopic = "/global_costmap/costmap";
inline constexpr const char* kStvlCostmapTopic = "/stvl/costmap";

enum class BagCompression { kNone, kBz2, kLz4, kZstd };  // ROS 1: none, bz2, lz4; ROS 2 (MCAP chunks): none, lz4, zstd
enum class BagFormat { kRos1, kRos2 };

// nav2_costmap_2d's cost -> OccupancyGrid value table: free 0 -> 0, lethal 254 -> 100, inscribed 253 -> 99,
// unknown 255 -> -1, and 1..252 -> 1 + 97 (c - 1) / 251.
std::vector<std::int8_t> occupancy_values(const mapping::Costmap2D& costmap);

// "none", "bz2", "lz4" or "zstd"; throws std::invalid_argument otherwise.
BagCompression parse_bag_compression(const std::string& name);
std::string to_string(BagCompression compression);
// "ros1" or "ros2"; empty: by the path (ros2 for a name ending in .mcap, ros1 otherwise).
BagFormat parse_bag_format(const std::string& name, const std::string& path);
// Where a ROS 2 export of `path` goes: the rosbag2 folder ("out/run.mcap" and "out/run" -> "out/run").
std::string ros2_bag_folder(const std::string& path);

// The topics a bag gets: "all", "default" (what a person opens to look at a run: depth image and camera_info,
// filtered clouds, voxels, costmap, tf, odometry, clock, ground truth, and a closed loop's /plan, /cmd_vel and
// /local_costmap/costmap, /global_costmap/costmap; not the full clouds */depth/points), or a
// comma-separated list of topics, globs ('*' matches anything, '/' too) and those two words.
class BagTopics {
 public:
  explicit BagTopics(const std::string& spec = "all");  // throws std::invalid_argument for a bad entry
  bool wants(const std::string& topic) const;
  const std::string& spec() const { return spec_; }

 private:
  std::string spec_;
  std::vector<std::string> patterns_;
};

// What both formats write; times and frames as above.
class BagSink {
 public:
  virtual ~BagSink() = default;
  struct CameraFrames {
    std::string camera = "camera";
    Eigen::Isometry3d T_base_camera_link = Eigen::Isometry3d::Identity();
    Eigen::Isometry3d T_camera_link_optical = Eigen::Isometry3d::Identity();
  };
  virtual void write_clock(double t_s) = 0;
  virtual void write_tf(double t_s, const Eigen::Isometry3d& T_map_odom, const Eigen::Isometry3d& T_odom_base) = 0;
  virtual void write_tf_static(const std::vector<CameraFrames>& cameras) = 0;
  virtual void write_odometry(double t_s, const Eigen::Isometry3d& T_odom_base, double v_mps, double omega_radps) = 0;
  virtual void write_ground_truth_pose(double t_s, const Eigen::Isometry3d& T_map_base) = 0;
  // The camera's image and info recorded at t_s with header stamp stamp_s (what its driver wrote: the capture time,
  // or another; issue 43); the unstamped forms stamp them at t_s.
  virtual void write_depth_image_stamped(double t_s, double stamp_s, const sensors::CameraIntrinsics& intrinsics,
                                         const std::vector<std::uint16_t>& depth_mm, const std::string& camera) = 0;
  virtual void write_camera_info_stamped(double t_s, double stamp_s, const sensors::CameraIntrinsics& intrinsics,
                                         const std::string& camera) = 0;
  void write_depth_image(double t_s, const sensors::CameraIntrinsics& intrinsics,
                         const std::vector<std::uint16_t>& depth_mm, const std::string& camera = "camera") {
    write_depth_image_stamped(t_s, t_s, intrinsics, depth_mm, camera);
  }
  void write_camera_info(double t_s, const sensors::CameraIntrinsics& intrinsics,
                         const std::string& camera = "camera") {
    write_camera_info_stamped(t_s, t_s, intrinsics, camera);
  }
  virtual void write_points(const std::string& topic, double t_s, const std::string& frame_id,
                            const Eigen::Matrix3Xf& points, bool latched = false) = 0;
  // The same cloud recorded at t_s with header stamp stamp_s: a reading taken at stamp_s (so tf gives the pose it
  // was taken at) that a map update applied at t_s.
  virtual void write_points_stamped(const std::string& topic, double t_s, double stamp_s, const std::string& frame_id,
                                    const Eigen::Matrix3Xf& points) = 0;
  // nav_msgs/OccupancyGrid on `topic` (absolute), frame map, row-major from the origin cell; costs translated as
  // nav2's costmap publisher does (occupancy_values()).
  virtual void write_costmap_on(const std::string& topic, double t_s, const mapping::Costmap2D& costmap) = 0;
  // The layer's costmap: write_costmap_on(kStvlCostmapTopic, ...).
  void write_costmap(double t_s, const mapping::Costmap2D& costmap) {
    write_costmap_on(kStvlCostmapTopic, t_s, costmap);
  }
  // nav_msgs/Path on `topic` (absolute), frame map, as planner_server publishes /plan: one
  // geometry_msgs/PoseStamped per pose (x_m, y_m, yaw_rad in the map frame; z = 0, the orientation a rotation by
  // yaw about z), every pose's header the path's. An empty path is written as one without poses.
  virtual void write_path(const std::string& topic, double t_s, const std::vector<Eigen::Vector3d>& poses_xy_yaw_W) = 0;
  // geometry_msgs/Twist on `topic` (absolute), as nav2's controller publishes /cmd_vel (unstamped, Jazzy's
  // default): linear.x = v_mps, angular.z = omega_radps, the rest 0. Recorded at t_s + kBagTimeOffset_s.
  virtual void write_twist(const std::string& topic, double t_s, double v_mps, double omega_radps) = 0;
  // Finishes the export and gives it its final name; further writes throw.
  virtual void close() = 0;
  virtual std::uint64_t bytes_written() const = 0;
  // The final path: the bag file (ROS 1) or the rosbag2 folder (ROS 2).
  virtual const std::string& path() const = 0;
};

// A ROS 1 bag at path, or a rosbag2 folder (ros2_bag_folder(path)) written as <folder>.active until close().
// kNone..kLz4 for ROS 1, kNone, kLz4, kZstd for ROS 2; throws std::invalid_argument for another.
std::unique_ptr<BagSink> make_bag_writer(const std::string& path, BagFormat format, BagCompression compression);

class BagWriter : public BagSink {
 public:
  // Writes to path + ".active"; throws std::runtime_error if it cannot be created.
  BagWriter(std::string path, BagCompression compression);
  // Without close() (an exception, an interruption) only path + ".active" is left, never path.
  ~BagWriter();
  BagWriter(const BagWriter&) = delete;
  BagWriter& operator=(const BagWriter&) = delete;

  // /clock rosgraph_msgs/Clock.
  void write_clock(double t_s) override;
  // /tf: map -> odom and odom -> base_link in one tf2_msgs/TFMessage.
  void write_tf(double t_s, const Eigen::Isometry3d& T_map_odom, const Eigen::Isometry3d& T_odom_base) override;
  // /tf_static (latched), stamped at t = 0, one message for every camera: base_link -> <camera>_link ->
  // <camera>_depth_optical_frame.
  void write_tf_static(const std::vector<CameraFrames>& cameras) override;
  void write_tf_static(const Eigen::Isometry3d& T_base_camera_link, const Eigen::Isometry3d& T_camera_link_optical) {
    write_tf_static({{"camera", T_base_camera_link, T_camera_link_optical}});
  }
  // /odom nav_msgs/Odometry, frame odom, child base_link; twist in base_link (v along x, omega about z).
  void write_odometry(double t_s, const Eigen::Isometry3d& T_odom_base, double v_mps, double omega_radps) override;
  // /ground_truth/pose geometry_msgs/PoseStamped, frame map.
  void write_ground_truth_pose(double t_s, const Eigen::Isometry3d& T_map_base) override;
  // /<camera>/depth/image_rect_raw 16UC1 (mm, 0 = invalid; sensors::depth_to_millimetres), row-major top row
  // first, frame <camera>_depth_optical_frame. depth_mm.size() must be the intrinsics' width * height.
  void write_depth_image_stamped(double t_s, double stamp_s, const sensors::CameraIntrinsics& intrinsics,
                                 const std::vector<std::uint16_t>& depth_mm, const std::string& camera) override;
  // /<camera>/depth/camera_info: plumb_bob with zero distortion, K, R = I, P = [K | 0].
  void write_camera_info_stamped(double t_s, double stamp_s, const sensors::CameraIntrinsics& intrinsics,
                                 const std::string& camera) override;
  using BagSink::write_camera_info;
  using BagSink::write_depth_image;
  // sensor_msgs/PointCloud2 with fields x y z float32, unorganized (height 1); is_dense when all finite.
  void write_points(const std::string& topic, double t_s, const std::string& frame_id, const Eigen::Matrix3Xf& points,
                    bool latched = false) override;
  void write_points_stamped(const std::string& topic, double t_s, double stamp_s, const std::string& frame_id,
                            const Eigen::Matrix3Xf& points) override;
  // nav_msgs/OccupancyGrid, frame map, row-major from the origin cell; costs translated as nav2's costmap
  // publisher does (occupancy_values()).
  void write_costmap_on(const std::string& topic, double t_s, const mapping::Costmap2D& costmap) override;
  // nav_msgs/Path, frame map; each pose's header (seq included) is the path's.
  void write_path(const std::string& topic, double t_s, const std::vector<Eigen::Vector3d>& poses_xy_yaw_W) override;
  // geometry_msgs/Twist (no header: ROS 1's /cmd_vel type).
  void write_twist(const std::string& topic, double t_s, double v_mps, double omega_radps) override;

  // Writes the index, closes the file and renames path.active -> path. Further writes throw.
  void close() override;
  // Bytes in the file so far (the final size after close()).
  std::uint64_t bytes_written() const override;
  const std::string& path() const override { return path_; }

 private:
  void write_cloud(const std::string& topic, double t_s, double stamp_s, const std::string& frame_id,
                   const Eigen::Matrix3Xf& points, bool latched);
  struct Impl;
  std::string path_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace stvl::recording

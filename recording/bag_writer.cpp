#include "recording/bag_writer.hpp"

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/Twist.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <rosbag/bag.h>

#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>
#include <memory>
#include <vector>

#include <boost/make_shared.hpp>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "common/units.hpp"

// Debian 12 packages no C++ header for rosgraph_msgs/Clock (libros-rosgraph-msgs-dev is not a dependency), so the
// message is declared here: md5sum, datatype and definition match rosgraph_msgs/Clock exactly, so readers
// (rosbag, rqt_bag, rosbag play) treat it as the real type.
namespace stvl::recording::detail {
struct ClockMsg {
  ros::Time clock;
};
}  // namespace stvl::recording::detail

namespace ros {
namespace message_traits {
template <>
struct MD5Sum<stvl::recording::detail::ClockMsg> {
  static const char* value() { return "a9c97c1d230cfc112e270351a944ee47"; }
  static const char* value(const stvl::recording::detail::ClockMsg&) { return value(); }
};
template <>
struct DataType<stvl::recording::detail::ClockMsg> {
  static const char* value() { return "rosgraph_msgs/Clock"; }
  static const char* value(const stvl::recording::detail::ClockMsg&) { return value(); }
};
template <>
struct Definition<stvl::recording::detail::ClockMsg> {
  static const char* value() {
    return "# roslib/Clock is used for publishing simulated time in ROS. \n"
           "# This message simply communicates the current time.\n"
           "# For more information, see http://www.ros.org/wiki/Clock\n"
           "time clock\n";
  }
  static const char* value(const stvl::recording::detail::ClockMsg&) { return value(); }
};
}  // namespace message_traits
namespace serialization {
template <>
struct Serializer<stvl::recording::detail::ClockMsg> {
  template <typename Stream, typename T>
  inline static void allInOne(Stream& stream, T m) {
    stream.next(m.clock);
  }
  ROS_DECLARE_ALLINONE_SERIALIZER
};
}  // namespace serialization
}  // namespace ros

namespace stvl::recording {
namespace {

constexpr const char* kCallerId = "/stvl_bench";

ros::Time to_ros_time(double t_s) {
  if (!std::isfinite(t_s) || t_s < 0.0 || t_s > 4.0e9) {
    throw std::invalid_argument("BagWriter: time must be finite and in [0, 4e9] s, got " + std::to_string(t_s));
  }
  const auto total_ns = static_cast<std::int64_t>(std::llround((t_s + kBagTimeOffset_s) * kNanosecondsPerSecond));
  return ros::Time(static_cast<std::uint32_t>(total_ns / kWholeNanosecondsPerSecond),
                   static_cast<std::uint32_t>(total_ns % kWholeNanosecondsPerSecond));
}

void require_finite_pose(const Eigen::Isometry3d& T, const char* name) {
  if (!T.matrix().allFinite()) {
    throw std::invalid_argument(std::string("BagWriter: pose ") + name + " is not finite");
  }
}

geometry_msgs::Pose to_pose(const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q = Eigen::Quaterniond(T.linear()).normalized();
  geometry_msgs::Pose pose;
  pose.position.x = T.translation().x();
  pose.position.y = T.translation().y();
  pose.position.z = T.translation().z();
  pose.orientation.x = q.x();
  pose.orientation.y = q.y();
  pose.orientation.z = q.z();
  pose.orientation.w = q.w();
  return pose;
}

geometry_msgs::TransformStamped to_transform(const ros::Time& stamp, const std::string& parent,
                                             const std::string& child, const Eigen::Isometry3d& T_parent_child) {
  const geometry_msgs::Pose pose = to_pose(T_parent_child);
  geometry_msgs::TransformStamped tf;
  tf.header.stamp = stamp;
  tf.header.frame_id = parent;
  tf.child_frame_id = child;
  tf.transform.translation.x = pose.position.x;
  tf.transform.translation.y = pose.position.y;
  tf.transform.translation.z = pose.position.z;
  tf.transform.rotation = pose.orientation;
  return tf;
}

void require_topic(const std::string& topic) {
  if (topic.size() < 2 || topic.front() != '/') {
    throw std::invalid_argument("BagWriter: topic must be an absolute name like /camera/depth/points or /plan, got '" +
                                topic + "'");
  }
}

void require_image_size(int width, int height, std::size_t size, const char* what) {
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument(std::string("BagWriter: ") + what + " size must be positive, got " +
                                std::to_string(width) + "x" + std::to_string(height));
  }
  if (size != static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {
    throw std::invalid_argument(std::string("BagWriter: ") + what + " has " + std::to_string(size) +
                                " values, expected " + std::to_string(width) + "x" + std::to_string(height));
  }
}

}  // namespace

struct BagWriter::Impl {
  // A heap Bag so that one whose write or close failed (a full disk) can be abandoned: rosbag's ~Bag() retries
  // close(), which throws again from inside a destructor and would terminate the process.
  std::unique_ptr<rosbag::Bag> bag = std::make_unique<rosbag::Bag>();
  std::string active_path;
  bool open = false;
  std::uint64_t final_size = 0;
  std::map<std::string, std::uint32_t> seq_by_topic;
  std::map<std::string, boost::shared_ptr<ros::M_string>> latched_headers;
  // Reused between frames so the large buffers keep their capacity.
  sensor_msgs::Image image;
  sensor_msgs::PointCloud2 cloud;

  void abandon() {
    open = false;
    static auto* failed = new std::vector<std::unique_ptr<rosbag::Bag>>;  // never destroyed, on purpose
    failed->push_back(std::move(bag));
  }

  void require_open() const {
    if (!open) throw std::runtime_error("BagWriter: write after close() of '" + active_path + "'");
  }

  std_msgs::Header header(const std::string& topic, const ros::Time& stamp, const std::string& frame_id) {
    std_msgs::Header h;
    h.seq = seq_by_topic[topic]++;
    h.stamp = stamp;
    h.frame_id = frame_id;
    return h;
  }

  template <typename Msg>
  void write(const std::string& topic, const ros::Time& time, const Msg& msg, bool latched = false) {
    require_open();
    try {
      if (!latched) {
        bag->write(topic, time, msg);
        return;
      }
      auto& connection_header = latched_headers[topic];
      if (!connection_header) {
        connection_header = boost::make_shared<ros::M_string>();
        (*connection_header)["type"] = ros::message_traits::datatype(msg);
        (*connection_header)["md5sum"] = ros::message_traits::md5sum(msg);
        (*connection_header)["message_definition"] = ros::message_traits::definition(msg);
        (*connection_header)["callerid"] = kCallerId;
        (*connection_header)["latching"] = "1";
      }
      bag->write(topic, time, msg, connection_header);
    } catch (const rosbag::BagException& e) {
      abandon();
      throw std::runtime_error("BagWriter: writing " + topic + " to '" + active_path + "' failed: " + e.what());
    }
  }
};

BagWriter::BagWriter(std::string path, BagCompression compression)
    : path_(std::move(path)), impl_(std::make_unique<Impl>()) {
  if (path_.empty()) throw std::invalid_argument("BagWriter: empty output path");
  if (compression == BagCompression::kZstd)
    throw std::invalid_argument(
        "ROS 1 bags have no zstd compression (none, bz2 or lz4; zstd is for --bag-format ros2)");
  impl_->active_path = path_ + ".active";
  try {
    impl_->bag->open(impl_->active_path, rosbag::bagmode::Write);
  } catch (const rosbag::BagException& e) {
    throw std::runtime_error("cannot create bag '" + impl_->active_path + "': " + e.what());
  }
  switch (compression) {
    case BagCompression::kNone: impl_->bag->setCompression(rosbag::compression::Uncompressed); break;
    case BagCompression::kBz2: impl_->bag->setCompression(rosbag::compression::BZ2); break;
    case BagCompression::kLz4: impl_->bag->setCompression(rosbag::compression::LZ4); break;
    case BagCompression::kZstd: break;  // refused above
  }
  impl_->open = true;
}

BagWriter::~BagWriter() {
  if (impl_ && impl_->open) {
    try {
      impl_->bag->close();  // indexes what was written; the file keeps its .active name
    } catch (...) {
      impl_->abandon();
    }
  }
}

void BagWriter::write_clock(double t_s) {
  detail::ClockMsg msg;
  msg.clock = to_ros_time(t_s);
  impl_->write("/clock", msg.clock, msg);
}

void BagWriter::write_tf(double t_s, const Eigen::Isometry3d& T_map_odom, const Eigen::Isometry3d& T_odom_base) {
  require_finite_pose(T_map_odom, "T_map_odom");
  require_finite_pose(T_odom_base, "T_odom_base");
  const ros::Time stamp = to_ros_time(t_s);
  tf2_msgs::TFMessage msg;
  msg.transforms.push_back(to_transform(stamp, kMapFrame, kOdomFrame, T_map_odom));
  msg.transforms.push_back(to_transform(stamp, kOdomFrame, kBaseFrame, T_odom_base));
  impl_->write("/tf", stamp, msg);
}

void BagWriter::write_tf_static(const std::vector<CameraFrames>& cameras) {
  const ros::Time stamp = to_ros_time(0.0);
  tf2_msgs::TFMessage msg;
  for (const auto& c : cameras) {
    require_finite_pose(c.T_base_camera_link, "T_base_camera_link");
    require_finite_pose(c.T_camera_link_optical, "T_camera_link_optical");
    const std::string link = camera_link_frame(c.camera);
    msg.transforms.push_back(to_transform(stamp, kBaseFrame, link, c.T_base_camera_link));
    msg.transforms.push_back(to_transform(stamp, link, camera_optical_frame(c.camera), c.T_camera_link_optical));
  }
  impl_->write("/tf_static", stamp, msg, /*latched=*/true);
}

void BagWriter::write_odometry(double t_s, const Eigen::Isometry3d& T_odom_base, double v_mps, double omega_radps) {
  require_finite_pose(T_odom_base, "T_odom_base");
  if (!std::isfinite(v_mps) || !std::isfinite(omega_radps)) {
    throw std::invalid_argument("BagWriter: odometry twist is not finite");
  }
  const std::string topic = "/odom";
  const ros::Time stamp = to_ros_time(t_s);
  nav_msgs::Odometry msg;
  msg.header = impl_->header(topic, stamp, kOdomFrame);
  msg.child_frame_id = kBaseFrame;
  msg.pose.pose = to_pose(T_odom_base);
  msg.twist.twist.linear.x = v_mps;
  msg.twist.twist.angular.z = omega_radps;
  impl_->write(topic, stamp, msg);
}

void BagWriter::write_ground_truth_pose(double t_s, const Eigen::Isometry3d& T_map_base) {
  require_finite_pose(T_map_base, "T_map_base");
  const std::string topic = "/ground_truth/pose";
  const ros::Time stamp = to_ros_time(t_s);
  geometry_msgs::PoseStamped msg;
  msg.header = impl_->header(topic, stamp, kMapFrame);
  msg.pose = to_pose(T_map_base);
  impl_->write(topic, stamp, msg);
}

void BagWriter::write_depth_image_stamped(double t_s, double stamp_s, const sensors::CameraIntrinsics& intrinsics,
                                          const std::vector<std::uint16_t>& depth_mm, const std::string& camera) {
  const int width = intrinsics.width, height = intrinsics.height;
  require_image_size(width, height, depth_mm.size(), "depth image");
  const std::string topic = camera_topic(camera, "depth/image_rect_raw");
  const ros::Time stamp = to_ros_time(t_s);
  sensor_msgs::Image& msg = impl_->image;
  msg.header = impl_->header(topic, to_ros_time(stamp_s), camera_optical_frame(camera));
  msg.width = static_cast<std::uint32_t>(width);
  msg.height = static_cast<std::uint32_t>(height);
  msg.encoding = "16UC1";
  msg.is_bigendian = 0;  // memcpy below writes host order; x86-64 and aarch64 are little-endian
  msg.step = static_cast<std::uint32_t>(width) * sizeof(std::uint16_t);
  msg.data.resize(depth_mm.size() * sizeof(std::uint16_t));
  std::memcpy(msg.data.data(), depth_mm.data(), msg.data.size());
  impl_->write(topic, stamp, msg);
}

void BagWriter::write_camera_info_stamped(double t_s, double stamp_s, const sensors::CameraIntrinsics& intrinsics,
                                          const std::string& camera) {
  const int width = intrinsics.width, height = intrinsics.height;
  const double fx_px = intrinsics.fx, fy_px = intrinsics.fy, cx_px = intrinsics.cx, cy_px = intrinsics.cy;
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument("BagWriter: camera_info size must be positive");
  }
  if (!(fx_px > 0.0) || !(fy_px > 0.0) || !std::isfinite(fx_px) || !std::isfinite(fy_px) || !std::isfinite(cx_px) ||
      !std::isfinite(cy_px)) {
    throw std::invalid_argument("BagWriter: camera_info needs finite intrinsics with fx, fy > 0");
  }
  const std::string topic = camera_topic(camera, "depth/camera_info");
  const ros::Time stamp = to_ros_time(t_s);
  sensor_msgs::CameraInfo msg;
  msg.header = impl_->header(topic, to_ros_time(stamp_s), camera_optical_frame(camera));
  msg.width = static_cast<std::uint32_t>(width);
  msg.height = static_cast<std::uint32_t>(height);
  msg.distortion_model = "plumb_bob";
  msg.D.assign(5, 0.0);
  msg.K = {fx_px, 0.0, cx_px, 0.0, fy_px, cy_px, 0.0, 0.0, 1.0};
  msg.R = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  msg.P = {fx_px, 0.0, cx_px, 0.0, 0.0, fy_px, cy_px, 0.0, 0.0, 0.0, 1.0, 0.0};
  impl_->write(topic, stamp, msg);
}

void BagWriter::write_points(const std::string& topic, double t_s, const std::string& frame_id,
                             const Eigen::Matrix3Xf& points, bool latched) {
  write_cloud(topic, t_s, t_s, frame_id, points, latched);
}

void BagWriter::write_points_stamped(const std::string& topic, double t_s, double stamp_s, const std::string& frame_id,
                                     const Eigen::Matrix3Xf& points) {
  write_cloud(topic, t_s, stamp_s, frame_id, points, false);
}

void BagWriter::write_cloud(const std::string& topic, double t_s, double stamp_s, const std::string& frame_id,
                            const Eigen::Matrix3Xf& points, bool latched) {
  require_topic(topic);
  if (frame_id.empty()) throw std::invalid_argument("BagWriter: empty frame_id for " + topic);
  const ros::Time stamp = to_ros_time(stamp_s);
  sensor_msgs::PointCloud2& msg = impl_->cloud;
  msg.header = impl_->header(topic, stamp, frame_id);
  if (msg.fields.empty()) {
    const char* names[3] = {"x", "y", "z"};
    for (std::uint32_t i = 0; i < 3; ++i) {
      sensor_msgs::PointField field;
      field.name = names[i];
      field.offset = i * sizeof(float);
      field.datatype = sensor_msgs::PointField::FLOAT32;
      field.count = 1;
      msg.fields.push_back(field);
    }
  }
  const auto n = static_cast<std::uint32_t>(points.cols());
  msg.height = 1;
  msg.width = n;
  msg.is_bigendian = false;
  msg.point_step = 3 * sizeof(float);
  msg.row_step = msg.point_step * n;
  msg.is_dense = points.allFinite();
  // Column-major 3xN floats are exactly the packed x y z records of the cloud.
  msg.data.resize(static_cast<std::size_t>(msg.row_step));
  if (n > 0) std::memcpy(msg.data.data(), points.data(), msg.data.size());
  impl_->write(topic, to_ros_time(t_s), msg, latched);
}

void BagWriter::write_costmap_on(const std::string& topic, double t_s, const mapping::Costmap2D& costmap) {
  require_topic(topic);
  require_image_size(costmap.width, costmap.height, costmap.cells.size(), "costmap");
  if (!(costmap.resolution_m > 0.0) || !std::isfinite(costmap.resolution_m) || !costmap.origin_m.allFinite()) {
    throw std::invalid_argument("BagWriter: costmap needs a finite origin and a resolution > 0");
  }
  const ros::Time stamp = to_ros_time(t_s);
  nav_msgs::OccupancyGrid msg;
  msg.header = impl_->header(topic, stamp, kMapFrame);
  msg.info.map_load_time = stamp;
  msg.info.resolution = static_cast<float>(costmap.resolution_m);
  msg.info.width = static_cast<std::uint32_t>(costmap.width);
  msg.info.height = static_cast<std::uint32_t>(costmap.height);
  msg.info.origin.position.x = costmap.origin_m.x();
  msg.info.origin.position.y = costmap.origin_m.y();
  msg.info.origin.orientation.w = 1.0;
  msg.data = occupancy_values(costmap);
  impl_->write(topic, stamp, msg);
}

void BagWriter::write_path(const std::string& topic, double t_s, const std::vector<Eigen::Vector3d>& poses_xy_yaw_W) {
  require_topic(topic);
  for (const auto& p : poses_xy_yaw_W) {
    if (!p.allFinite()) throw std::invalid_argument("BagWriter: a pose of the path on " + topic + " is not finite");
  }
  const ros::Time stamp = to_ros_time(t_s);
  nav_msgs::Path msg;
  msg.header = impl_->header(topic, stamp, kMapFrame);
  msg.poses.resize(poses_xy_yaw_W.size());
  for (std::size_t i = 0; i < poses_xy_yaw_W.size(); ++i) {
    const Eigen::Vector3d& p = poses_xy_yaw_W[i];
    geometry_msgs::PoseStamped& pose = msg.poses[i];
    pose.header = msg.header;
    pose.pose.position.x = p.x();
    pose.pose.position.y = p.y();
    pose.pose.orientation.z = std::sin(0.5 * p.z());
    pose.pose.orientation.w = std::cos(0.5 * p.z());
  }
  impl_->write(topic, stamp, msg);
}

void BagWriter::write_twist(const std::string& topic, double t_s, double v_mps, double omega_radps) {
  require_topic(topic);
  if (!std::isfinite(v_mps) || !std::isfinite(omega_radps)) {
    throw std::invalid_argument("BagWriter: the twist on " + topic + " is not finite");
  }
  geometry_msgs::Twist msg;
  msg.linear.x = v_mps;
  msg.angular.z = omega_radps;
  impl_->write(topic, to_ros_time(t_s), msg);
}

void BagWriter::close() {
  impl_->require_open();
  impl_->open = false;
  try {
    impl_->bag->close();
  } catch (const rosbag::BagException& e) {
    impl_->abandon();
    throw std::runtime_error("BagWriter: closing '" + impl_->active_path + "' failed: " + e.what());
  }
  std::error_code ec;
  std::filesystem::rename(impl_->active_path, path_, ec);
  if (ec) {
    throw std::runtime_error("BagWriter: cannot rename '" + impl_->active_path + "' to '" + path_ +
                             "': " + ec.message());
  }
  impl_->final_size = std::filesystem::file_size(path_, ec);
}

std::uint64_t BagWriter::bytes_written() const { return impl_->open ? impl_->bag->getSize() : impl_->final_size; }

}  // namespace stvl::recording

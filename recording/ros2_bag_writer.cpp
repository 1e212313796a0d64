// rosbag2 export: a folder with metadata.yaml (as Jazzy writes it, version 9) and one MCAP file (profile ros2,
// ros2msg schemas with their dependencies, cdr channels with offered-QoS metadata, a "rosbag2" metadata record).
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>

#include "common/atomic_file.hpp"
#include "common/units.hpp"
#include "recording/cdr.hpp"
#include "recording/detail.hpp"
#include "recording/mcap.hpp"
#include "recording/ros2_msgs.hpp"
#include "recording/type_hash.hpp"

namespace stvl::recording::detail {
namespace {

namespace fs = std::filesystem;

// rosbag2's offered QoS (Jazzy's names): reliable, volatile, or transient local (latched: /tf_static).
std::string qos_yaml(bool transient_local, const std::string& indent) {
  const std::string inf = "\n" + indent + "    sec: 9223372036\n" + indent + "    nsec: 854775807";
  return indent + "- history: keep_last\n" + indent + "  depth: " + (transient_local ? "1" : "10") + "\n" + indent +
         "  reliability: reliable\n" + indent + "  durability: " + (transient_local ? "transient_local" : "volatile") +
         "\n" + indent + "  deadline:" + inf + "\n" + indent + "  lifespan:" + inf + "\n" + indent +
         "  liveliness: automatic\n" + indent + "  liveliness_lease_duration:" + inf + "\n" + indent +
         "  avoid_ros_namespace_conventions: false";
}

std::uint64_t stamp_ns(double t_s) {
  if (!std::isfinite(t_s) || t_s < 0.0 || t_s > 2.0e9)
    throw std::invalid_argument("BagWriter: time must be finite and in [0, 2e9] s, got " + std::to_string(t_s));
  return static_cast<std::uint64_t>(std::llround((t_s + kBagTimeOffset_s) * kNanosecondsPerSecond));
}

void require_finite(const Eigen::Isometry3d& T, const char* name) {
  if (!T.matrix().allFinite()) throw std::invalid_argument(std::string("BagWriter: pose ") + name + " is not finite");
}

void require_topic(const std::string& topic) {
  if (topic.size() < 2 || topic.front() != '/')
    throw std::invalid_argument("BagWriter: topic must be an absolute name like /camera/depth/points or /plan, got '" +
                                topic + "'");
}

class Ros2BagWriter final : public BagSink {
 public:
  Ros2BagWriter(std::string folder, BagCompression compression)
      : folder_(std::move(folder)), active_(folder_ + ".active") {
    if (folder_.empty()) throw std::invalid_argument("BagWriter: empty output path");
    McapCompression c = McapCompression::kZstd;
    if (compression == BagCompression::kNone) c = McapCompression::kNone;
    else if (compression == BagCompression::kLz4) c = McapCompression::kLz4;
    else if (compression == BagCompression::kBz2)
      throw std::invalid_argument("MCAP has no bz2 compression (none, lz4 or zstd; bz2 is for ROS 1 bags)");
    compression_ = compression;
    std::error_code ec;
    if (fs::exists(folder_, ec) &&
        (!fs::is_directory(folder_, ec) ||
         (!fs::is_empty(folder_, ec) && !fs::exists(fs::path(folder_) / "metadata.yaml", ec))))
      throw std::runtime_error("cannot write rosbag2 folder '" + folder_ + "': it exists and is not a rosbag2 folder");
    fs::remove_all(active_, ec);
    if (!fs::create_directories(active_, ec) && ec)
      throw std::runtime_error("cannot create rosbag2 folder '" + active_ + "': " + ec.message());
    file_name_ = fs::path(folder_).filename().string() + "_0.mcap";
    mcap_ = std::make_unique<McapWriter>((fs::path(active_) / file_name_).string(), c, "ros2", "stvl-bench");
  }

  void write_clock(double t_s) override {
    CdrWriter w(buf_);
    put_time(w, stamp_ns(t_s));
    write("/clock", "rosgraph_msgs/msg/Clock", stamp_ns(t_s));
  }
  void write_tf(double t_s, const Eigen::Isometry3d& T_map_odom, const Eigen::Isometry3d& T_odom_base) override {
    require_finite(T_map_odom, "T_map_odom"), require_finite(T_odom_base, "T_odom_base");
    const auto t = stamp_ns(t_s);
    CdrWriter w(buf_);
    w.put(std::uint32_t(2));
    put_transform(w, t, kMapFrame, kOdomFrame, T_map_odom);
    put_transform(w, t, kOdomFrame, kBaseFrame, T_odom_base);
    write("/tf", "tf2_msgs/msg/TFMessage", t);
  }
  void write_tf_static(const std::vector<CameraFrames>& cameras) override {
    const auto t = stamp_ns(0.0);
    CdrWriter w(buf_);
    w.put(static_cast<std::uint32_t>(2 * cameras.size()));
    for (const auto& c : cameras) {
      require_finite(c.T_base_camera_link, "T_base_camera_link"),
          require_finite(c.T_camera_link_optical, "T_camera_link_optical");
      put_transform(w, t, kBaseFrame, camera_link_frame(c.camera), c.T_base_camera_link);
      put_transform(w, t, camera_link_frame(c.camera), camera_optical_frame(c.camera), c.T_camera_link_optical);
    }
    write("/tf_static", "tf2_msgs/msg/TFMessage", t, true);
  }
  void write_odometry(double t_s, const Eigen::Isometry3d& T_odom_base, double v_mps, double omega_radps) override {
    require_finite(T_odom_base, "T_odom_base");
    if (!std::isfinite(v_mps) || !std::isfinite(omega_radps))
      throw std::invalid_argument("BagWriter: odometry twist is not finite");
    const auto t = stamp_ns(t_s);
    CdrWriter w(buf_);
    put_header(w, t, kOdomFrame);
    w.put_string(kBaseFrame);
    put_pose(w, T_odom_base);
    const double zeros[36] = {};
    w.put_array(zeros, 36);
    const double twist[6] = {v_mps, 0, 0, 0, 0, omega_radps};
    w.put_array(twist, 6);
    w.put_array(zeros, 36);
    write("/odom", "nav_msgs/msg/Odometry", t);
  }
  void write_ground_truth_pose(double t_s, const Eigen::Isometry3d& T_map_base) override {
    require_finite(T_map_base, "T_map_base");
    const auto t = stamp_ns(t_s);
    CdrWriter w(buf_);
    put_header(w, t, kMapFrame);
    put_pose(w, T_map_base);
    write("/ground_truth/pose", "geometry_msgs/msg/PoseStamped", t);
  }
  void write_depth_image_stamped(double t_s, double stamp_s, const sensors::CameraIntrinsics& k,
                                 const std::vector<std::uint16_t>& depth_mm, const std::string& camera) override {
    if (k.width <= 0 || k.height <= 0 || depth_mm.size() != std::size_t(k.width) * std::size_t(k.height))
      throw std::invalid_argument("BagWriter: depth image has " + std::to_string(depth_mm.size()) +
                                  " values, expected " + std::to_string(k.width) + "x" + std::to_string(k.height));
    const auto t = stamp_ns(t_s);
    CdrWriter w(buf_);
    put_header(w, stamp_ns(stamp_s), camera_optical_frame(camera));
    w.put(std::uint32_t(k.height)), w.put(std::uint32_t(k.width));
    w.put_string("16UC1");
    w.put(std::uint8_t(0));
    w.put(std::uint32_t(k.width * 2));
    w.put_bytes(depth_mm.data(), depth_mm.size() * 2);
    write(camera_topic(camera, "depth/image_rect_raw"), "sensor_msgs/msg/Image", t);
  }
  void write_camera_info_stamped(double t_s, double stamp_s, const sensors::CameraIntrinsics& k,
                                 const std::string& camera) override {
    if (k.width <= 0 || k.height <= 0 || !(k.fx > 0) || !(k.fy > 0) || !std::isfinite(k.fx) || !std::isfinite(k.fy) ||
        !std::isfinite(k.cx) || !std::isfinite(k.cy))
      throw std::invalid_argument("BagWriter: camera_info needs a positive size and finite intrinsics with fx, fy > 0");
    const auto t = stamp_ns(t_s);
    CdrWriter w(buf_);
    put_header(w, stamp_ns(stamp_s), camera_optical_frame(camera));
    w.put(std::uint32_t(k.height)), w.put(std::uint32_t(k.width));
    w.put_string("plumb_bob");
    w.put_sequence(std::vector<double>(5, 0.0));
    const double K[9] = {k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1}, R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    const double P[12] = {k.fx, 0, k.cx, 0, 0, k.fy, k.cy, 0, 0, 0, 1, 0};
    w.put_array(K, 9), w.put_array(R, 9), w.put_array(P, 12);
    w.put(std::uint32_t(0)), w.put(std::uint32_t(0));     // binning
    for (int i = 0; i < 4; ++i) w.put(std::uint32_t(0));  // roi
    w.put(std::uint8_t(0));                               // do_rectify
    write(camera_topic(camera, "depth/camera_info"), "sensor_msgs/msg/CameraInfo", t);
  }
  void write_points(const std::string& topic, double t_s, const std::string& frame_id, const Eigen::Matrix3Xf& points,
                    bool latched) override {
    write_cloud(topic, t_s, t_s, frame_id, points, latched);
  }
  void write_points_stamped(const std::string& topic, double t_s, double stamp_s, const std::string& frame_id,
                            const Eigen::Matrix3Xf& points) override {
    write_cloud(topic, t_s, stamp_s, frame_id, points, false);
  }
  void write_cloud(const std::string& topic, double t_s, double stamp_s, const std::string& frame_id,
                   const Eigen::Matrix3Xf& points, bool latched) {
    require_topic(topic);
    if (frame_id.empty()) throw std::invalid_argument("BagWriter: empty frame_id for " + topic);
    const auto n = static_cast<std::uint32_t>(points.cols());
    CdrWriter w(buf_);
    put_header(w, stamp_ns(stamp_s), frame_id);
    w.put(std::uint32_t(1)), w.put(n);
    w.put(std::uint32_t(3));
    for (std::uint32_t i = 0; i < 3; ++i) {
      w.put_string(std::string(1, char('x' + i)));
      w.put(std::uint32_t(4 * i)), w.put(std::uint8_t(7)), w.put(std::uint32_t(1));  // FLOAT32, count 1
    }
    w.put(std::uint8_t(0));
    w.put(std::uint32_t(12)), w.put(12 * n);
    w.put_bytes(points.data(), std::size_t(12) * n);  // 3xN column-major floats are the packed x y z records
    w.put(std::uint8_t(points.allFinite() ? 1 : 0));
    write(topic, "sensor_msgs/msg/PointCloud2", stamp_ns(t_s), latched);
  }
  void write_costmap_on(const std::string& topic, double t_s, const mapping::Costmap2D& costmap) override {
    require_topic(topic);
    if (costmap.width <= 0 || costmap.height <= 0 ||
        costmap.cells.size() != std::size_t(costmap.width) * costmap.height)
      throw std::invalid_argument("BagWriter: costmap size disagrees with its cells");
    if (!(costmap.resolution_m > 0.0) || !std::isfinite(costmap.resolution_m) || !costmap.origin_m.allFinite())
      throw std::invalid_argument("BagWriter: costmap needs a finite origin and a resolution > 0");
    const auto t = stamp_ns(t_s);
    CdrWriter w(buf_);
    put_header(w, t, kMapFrame);
    put_time(w, t);
    w.put(static_cast<float>(costmap.resolution_m));
    w.put(std::uint32_t(costmap.width)), w.put(std::uint32_t(costmap.height));
    Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
    origin.translation() << costmap.origin_m.x(), costmap.origin_m.y(), 0.0;
    put_pose(w, origin);
    const std::vector<std::int8_t> values = occupancy_values(costmap);
    w.put_bytes(values.data(), values.size());
    write(topic, "nav_msgs/msg/OccupancyGrid", t);
  }
  void write_path(const std::string& topic, double t_s, const std::vector<Eigen::Vector3d>& poses_xy_yaw_W) override {
    require_topic(topic);
    for (const auto& p : poses_xy_yaw_W)
      if (!p.allFinite()) throw std::invalid_argument("BagWriter: a pose of the path on " + topic + " is not finite");
    const auto t = stamp_ns(t_s);
    CdrWriter w(buf_);
    put_header(w, t, kMapFrame);
    w.put(static_cast<std::uint32_t>(poses_xy_yaw_W.size()));
    for (const auto& p : poses_xy_yaw_W) {
      put_header(w, t, kMapFrame);  // planner_server gives every pose the path's header
      const double pose[7] = {p.x(), p.y(), 0.0, 0.0, 0.0, std::sin(0.5 * p.z()), std::cos(0.5 * p.z())};
      w.put_array(pose, 7);
    }
    write(topic, "nav_msgs/msg/Path", t);
  }
  void write_twist(const std::string& topic, double t_s, double v_mps, double omega_radps) override {
    require_topic(topic);
    if (!std::isfinite(v_mps) || !std::isfinite(omega_radps))
      throw std::invalid_argument("BagWriter: the twist on " + topic + " is not finite");
    const auto t = stamp_ns(t_s);
    CdrWriter w(buf_);
    const double twist[6] = {v_mps, 0, 0, 0, 0, omega_radps};  // linear x y z, angular x y z
    w.put_array(twist, 6);
    write(topic, "geometry_msgs/msg/Twist", t);
  }

  void close() override {
    if (!mcap_) throw std::runtime_error("BagWriter: write after close() of '" + active_ + "'");
    const std::string yaml = metadata_yaml();
    mcap_->write_metadata("rosbag2", {{"serialized_metadata", yaml}, {"ROS_DISTRO", "jazzy"}});
    mcap_->close();
    final_size_ = mcap_->bytes_written();
    mcap_.reset();
    write_file_atomically((fs::path(active_) / "metadata.yaml").string(), yaml);
    std::error_code ec;
    fs::remove_all(folder_, ec);
    fs::rename(active_, folder_, ec);
    if (ec)
      throw std::runtime_error("BagWriter: cannot rename '" + active_ + "' to '" + folder_ + "': " + ec.message());
  }
  std::uint64_t bytes_written() const override { return mcap_ ? mcap_->bytes_written() : final_size_; }
  const std::string& path() const override { return folder_; }

 private:
  struct Topic {
    std::uint16_t channel = 0;
    std::string type;
    std::string type_hash;  // RIHS01 (type_hash.hpp); empty when it cannot be computed, as rosbag2 writes it
    bool latched = false;
    std::uint64_t count = 0;
    std::uint32_t sequence = 0;
  };

  static void put_time(CdrWriter& w, std::uint64_t ns) {
    w.put(static_cast<std::int32_t>(ns / kWholeNanosecondsPerSecond));
    w.put(static_cast<std::uint32_t>(ns % kWholeNanosecondsPerSecond));
  }
  static void put_header(CdrWriter& w, std::uint64_t ns, const std::string& frame) {
    put_time(w, ns), w.put_string(frame);
  }
  static void put_pose(CdrWriter& w, const Eigen::Isometry3d& T) {
    const Eigen::Quaterniond q = Eigen::Quaterniond(T.linear()).normalized();
    const double v[7] = {T.translation().x(), T.translation().y(), T.translation().z(), q.x(), q.y(), q.z(), q.w()};
    w.put_array(v, 7);
  }
  static void put_transform(CdrWriter& w, std::uint64_t ns, const std::string& parent, const std::string& child,
                            const Eigen::Isometry3d& T) {
    put_header(w, ns, parent);
    w.put_string(child);
    put_pose(w, T);
  }

  void write(const std::string& topic, const std::string& type, std::uint64_t t_ns, bool latched = false) {
    if (!mcap_) throw std::runtime_error("BagWriter: write after close() of '" + active_ + "'");
    auto it = topics_.find(topic);
    if (it == topics_.end()) {
      auto& schema = schemas_[type];
      if (!schema) schema = mcap_->add_schema(type, "ros2msg", ros2_definition(type));
      Topic tp;
      tp.type = type, tp.latched = latched;
      // As rosbag2 writes it; our definitions are ROS 2's own field lists, so the hash is ROS 2's.
      tp.type_hash = ros2_type_hash_of_schema(type, "ros2msg", ros2_definition(type)).rihs01;
      // rosbag2's MCAP storage puts the hash in the channel's metadata too (as its own recordings have it).
      std::map<std::string, std::string> metadata = {{"offered_qos_profiles", qos_yaml(latched, "")}};
      if (!tp.type_hash.empty()) metadata["topic_type_hash"] = tp.type_hash;
      tp.channel = mcap_->add_channel(schema, topic, "cdr", metadata);
      it = topics_.emplace(topic, tp).first;
    }
    if (it->second.type != type) throw std::logic_error("BagWriter: " + topic + " written as two types");
    mcap_->write_message(it->second.channel, t_ns, t_ns, buf_);
    ++it->second.count;
    start_ns_ = std::min(start_ns_, t_ns), end_ns_ = std::max(end_ns_, t_ns);
  }

  std::string metadata_yaml() const {
    const std::uint64_t start = topics_.empty() ? 0 : start_ns_, duration = topics_.empty() ? 0 : end_ns_ - start_ns_;
    std::uint64_t total = 0;
    std::string topics;
    for (const auto& [name, t] : topics_) {
      total += t.count;
      topics += "    - topic_metadata:\n        name: " + name + "\n        type: " + t.type +
                "\n        serialization_format: cdr\n        offered_qos_profiles:\n" +
                qos_yaml(t.latched, "          ") +
                "\n        type_description_hash: " + (t.type_hash.empty() ? "\"\"" : t.type_hash) +
                "\n      message_count: " + std::to_string(t.count) + "\n";
    }
    const std::string times = "      starting_time:\n        nanoseconds_since_epoch: " + std::to_string(start) +
                              "\n      duration:\n        nanoseconds: " + std::to_string(duration) + "\n";
    return "rosbag2_bagfile_information:\n  version: 9\n  storage_identifier: mcap\n  duration:\n    nanoseconds: " +
           std::to_string(duration) + "\n  starting_time:\n    nanoseconds_since_epoch: " + std::to_string(start) +
           "\n  message_count: " + std::to_string(total) +
           "\n  topics_with_message_count:" + (topics.empty() ? " []\n" : "\n" + topics) +
           "  compression_format: \"\"\n  compression_mode: \"\"\n  relative_file_paths:\n    - " + file_name_ +
           "\n  files:\n    - path: " + file_name_ + "\n" + times + "      message_count: " + std::to_string(total) +
           "\n  custom_data: ~\n  ros_distro: jazzy\n";
  }

  std::string folder_, active_, file_name_;
  BagCompression compression_ = BagCompression::kZstd;
  std::unique_ptr<McapWriter> mcap_;
  std::map<std::string, Topic> topics_;
  std::map<std::string, std::uint16_t> schemas_;
  std::vector<std::uint8_t> buf_;
  std::uint64_t start_ns_ = ~0ull, end_ns_ = 0, final_size_ = 0;
};

}  // namespace

std::unique_ptr<BagSink> make_ros2_bag_writer(const std::string& folder, BagCompression compression) {
  return std::make_unique<Ros2BagWriter>(folder, compression);
}

}  // namespace stvl::recording::detail

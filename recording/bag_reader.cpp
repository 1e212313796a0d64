// ROS 1 bags through rosbag_storage: realsense-ros's layout (/camera/depth/..., /tf, /tf_static, odometry) and
// librealsense's recorder layout (/device_0/sensor_N/Depth_0/...).
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Float32.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <regex>
#include <set>
#include <stdexcept>

#include "recording/bag_common.hpp"
#include "recording/detail.hpp"

namespace stvl::recording::detail {
namespace {

constexpr double kTimeTolerance_s = 1e-6;

bool ends_with(const std::string& text, const std::string& tail) {
  return text.size() >= tail.size() && text.compare(text.size() - tail.size(), tail.size(), tail) == 0;
}

double to_seconds(const ros::Time& t) { return t.toSec(); }

// Every topic of a bag with its type and message count (`use` left empty).
std::vector<TopicSummary> bag_topics(rosbag::Bag& bag) {
  std::map<std::string, TopicSummary> topics;
  rosbag::View all(bag);
  for (const auto* c : all.getConnections())
    topics[c->topic] = TopicSummary{c->topic, c->datatype, 0, "ros1", "ros1msg", "", ""};
  for (auto& [name, t] : topics) t.messages = rosbag::View(bag, rosbag::TopicQuery(name)).size();
  std::vector<TopicSummary> out;
  for (auto& [name, t] : topics) out.push_back(t);
  return out;
}

class BagRecording final : public Recording {
 public:
  BagRecording(const std::string& path, const RecordingOptions& options) : options_(options) {
    info_.path = path;
    info_.files = {path};
    try {
      bag_.open(path, rosbag::bagmode::Read);
    } catch (const std::exception& e) {
      throw std::invalid_argument(path + ": cannot read the bag (truncated or corrupt?): " + e.what());
    }
    try {
      open();
    } catch (const rosbag::BagException& e) {
      throw std::invalid_argument(path + ": corrupt bag (while reading its index or messages): " + e.what());
    } catch (const ros::Exception& e) {
      throw std::invalid_argument(path + ": corrupt bag (while reading its messages): " + e.what());
    }
  }

  const RecordingInfo& info() const override { return info_; }

  bool next(RecordedFrame& frame) override {
    if (!view_ || done_) return false;
    boost::shared_ptr<sensor_msgs::Image> image;
    try {
      if (started_) ++it_;  // never past end(): rosbag's iterator crashes there
      started_ = true;
      if (it_ == view_->end()) {
        done_ = true;
        return false;
      }
      image = it_->instantiate<sensor_msgs::Image>();
    } catch (const std::exception& e) {
      throw std::invalid_argument(where() + ": frame " + std::to_string(index_) +
                                  " cannot be read (truncated or corrupt chunk?): " + e.what());
    }
    if (!image) throw std::invalid_argument(where() + ": message " + std::to_string(index_) + " is not an image");
    frame.index = index_;
    frame.stamp_s = to_seconds(image->header.stamp);
    frame.time_s = frame.stamp_s - info_.start_time_s;
    frame.intrinsics = intrinsics_at(frame.stamp_s);
    decode(*image, frame.intrinsics, frame.depth);
    pose_at(frame.stamp_s, index_, frame.T_fixed_camera, frame.T_fixed_base);
    ++index_;
    return true;
  }

 private:
  std::string where() const { return info_.path + ": " + info_.depth_topic; }

  using TopicTypes = std::map<std::string, std::string>;  // topic -> datatype

  // librealsense's recorder names its depth topics /device_N/sensor_N/Depth_N/image/data.
  static const std::regex& librealsense_depth() {
    static const std::regex kLibrealsense(R"(^/device_\d+/sensor_\d+/Depth_\d+/image/data$)");
    return kLibrealsense;
  }

  TopicTypes topic_types() {
    TopicTypes types;
    rosbag::View all(bag_);
    for (const auto* c : all.getConnections()) types[c->topic] = c->datatype;
    return types;
  }

  static std::vector<std::string> topic_names(const TopicTypes& types) {
    std::vector<std::string> topics;
    for (const auto& [t, type] : types) topics.push_back(t);
    return topics;
  }

  // Throws std::invalid_argument unless the bag has `topic` of `type` (naming the nearest topic when it is missing).
  void require_topic(const TopicTypes& types, const std::string& topic, const std::string& type,
                     const char* option) const {
    const auto it = types.find(topic);
    if (it == types.end()) {
      std::vector<std::string> same_type;  // the nearest of the expected type, else of all
      for (const auto& [t, ty] : types)
        if (ty == type) same_type.push_back(t);
      const std::string near = nearest_name(topic, same_type.empty() ? topic_names(types) : same_type);
      throw std::invalid_argument(
          info_.path + ": no topic " + topic + " (" + option + ")" +
          (same_type.empty() ? ", the bag has no " + type + " topic" : std::string()) +
          (near.empty() ? std::string(", the bag has no topics") : ", nearest existing topic: " + near));
    }
    if (it->second != type) {
      throw std::invalid_argument(info_.path + ": topic " + topic + " is " + it->second + ", expected " + type);
    }
  }

  void open() {
    const TopicTypes types = topic_types();
    choose_depth_topic(types);
    const std::string& depth = info_.depth_topic;
    const bool librealsense = std::regex_match(depth, librealsense_depth());
    info_.format = librealsense ? "ros1 bag (librealsense)" : "ros1 bag (realsense-ros)";
    choose_info_topic(types, librealsense);
    read_camera_infos();
    if (librealsense) read_depth_units(types);
    read_depth_frames();
    read_poses(types);
    info_.topics = bag_topics(bag_);
    for (auto& t : info_.topics) {
      if (t.name == depth) t.use = "depth";
      else if (t.name == info_.info_topic) t.use = "camera_info";
      else if (!options_.odom_topic.empty() && t.name == options_.odom_topic) t.use = "odometry";
      else if ((t.name == "/tf" || t.name == "/tf_static") && t.type == "tf2_msgs/TFMessage") t.use = t.name.substr(1);
      else if (librealsense && t.name == depth.substr(0, depth.find("/Depth_")) + "/option/Depth Units/value" &&
               t.type == "std_msgs/Float32")
        t.use = "depth_units";
    }
    // The first frame's pose now, so that a recording without one fails at open.
    Eigen::Isometry3d T_fixed_camera, T_fixed_base;
    pose_at(info_.start_time_s, 0, T_fixed_camera, T_fixed_base);
    it_ = view_->begin();
  }

  // The depth topic: --depth-topic, else the only realsense-ros or librealsense depth image topic.
  void choose_depth_topic(const TopicTypes& types) {
    if (!options_.depth_topic.empty()) {
      require_topic(types, options_.depth_topic, "sensor_msgs/Image", "--depth-topic");
      info_.depth_topic = options_.depth_topic;
      return;
    }
    std::vector<std::string> candidates;
    for (const auto& [t, type] : types) {
      if (type != "sensor_msgs/Image") continue;
      if (ends_with(t, "/depth/image_rect_raw") || ends_with(t, "/aligned_depth_to_color/image_raw") ||
          std::regex_match(t, librealsense_depth())) {
        candidates.push_back(t);
      }
    }
    if (candidates.empty()) {
      throw std::invalid_argument(info_.path +
                                  ": no depth topic (looked for */depth/image_rect_raw, "
                                  "*/aligned_depth_to_color/image_raw, /device_N/sensor_N/Depth_N/image/data; "
                                  "the bag has: " +
                                  join(topic_names(types)) + "); name one with --depth-topic");
    }
    if (candidates.size() > 1) {
      throw std::invalid_argument(info_.path + ": several depth topics: " + join(candidates) +
                                  "; choose one with --depth-topic");
    }
    info_.depth_topic = candidates.front();
  }

  // The camera info beside the depth topic: --info-topic, else the driver's name for it.
  void choose_info_topic(const TopicTypes& types, bool librealsense) {
    const std::string& depth = info_.depth_topic;
    if (!options_.info_topic.empty()) {
      require_topic(types, options_.info_topic, "sensor_msgs/CameraInfo", "--info-topic");
      info_.info_topic = options_.info_topic;
      return;
    }
    info_.info_topic = librealsense ? depth.substr(0, depth.size() - 11) + "/info/camera_info"
                                    : depth.substr(0, depth.rfind('/')) + "/camera_info";
    if (!types.count(info_.info_topic)) {
      throw std::invalid_argument(info_.path + ": no camera info for " + depth + " (expected " + info_.info_topic +
                                  "); name one with --info-topic");
    }
    require_topic(types, info_.info_topic, "sensor_msgs/CameraInfo", "camera info");
  }

  // Every camera info message's intrinsics, by stamp.
  void read_camera_infos() {
    rosbag::View view(bag_, rosbag::TopicQuery(info_.info_topic));
    for (const auto& m : view) {
      const auto msg = m.instantiate<sensor_msgs::CameraInfo>();
      if (!msg) continue;
      const std::string what = info_.path + ": " + info_.info_topic + " K";
      infos_.emplace_back(to_seconds(msg->header.stamp),
                          make_intrinsics(msg->width, msg->height, msg->K[0], msg->K[4], msg->K[2], msg->K[5],
                                          options_.rate_hz, options_, what));
    }
    std::stable_sort(infos_.begin(), infos_.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    if (infos_.empty()) throw std::invalid_argument(info_.path + ": " + info_.info_topic + " has no messages");
  }

  // librealsense's depth units (its first "Depth Units" option message), when the bag has them.
  void read_depth_units(const TopicTypes& types) {
    const std::string& depth = info_.depth_topic;
    const std::string units = depth.substr(0, depth.find("/Depth_")) + "/option/Depth Units/value";
    if (!types.count(units) || types.at(units) != "std_msgs/Float32") return;
    rosbag::View view(bag_, rosbag::TopicQuery(units));
    for (const auto& m : view) {
      if (const auto msg = m.instantiate<std_msgs::Float32>()) {
        if (!std::isfinite(msg->data) || !(msg->data > 0)) {
          throw std::invalid_argument(info_.path + ": " + units + " is " + std::to_string(msg->data) +
                                      ", expected a positive number of metres");
        }
        info_.depth_unit_m = msg->data;
        break;
      }
    }
  }

  // Depth frames: count, first and last stamps, encoding and frame_id of the first; the rate from the stamps.
  void read_depth_frames() {
    view_ = std::make_unique<rosbag::View>(bag_, rosbag::TopicQuery(info_.depth_topic));
    info_.frame_count = view_->size();
    if (info_.frame_count == 0) throw std::invalid_argument(where() + ": no depth images on the topic");
    {
      const auto first = view_->begin()->instantiate<sensor_msgs::Image>();
      if (!first) throw std::invalid_argument(where() + ": not a sensor_msgs/Image");
      rosbag::View::iterator last_it = view_->begin();
      for (auto it = view_->begin(); it != view_->end(); ++it) last_it = it;
      const auto last = last_it->instantiate<sensor_msgs::Image>();
      info_.encoding = first->encoding;
      bytes_per_pixel(first->encoding);  // rejects what is not depth before the first frame
      info_.camera_frame = strip_slash(first->header.frame_id);
      info_.start_time_s = to_seconds(first->header.stamp);
      info_.end_time_s = last ? to_seconds(last->header.stamp) : info_.start_time_s;
    }
    if (info_.frame_count > 1 && info_.end_time_s > info_.start_time_s) {
      const double rate_hz = (info_.frame_count - 1) / (info_.end_time_s - info_.start_time_s);
      for (auto& [t, k] : infos_) k.rate_hz = rate_hz;
    }
    info_.intrinsics = intrinsics_at(info_.start_time_s);
  }

  // /tf_static, /tf and --odom-topic into poses_, resolved against the depth frames.
  void read_poses(const TopicTypes& types) {
    // /tf_static and /tf.
    for (const char* topic : {"/tf_static", "/tf"}) {
      const auto it = types.find(topic);
      if (it == types.end() || it->second != "tf2_msgs/TFMessage") continue;
      const bool is_static = std::string(topic) == "/tf_static";
      rosbag::View view(bag_, rosbag::TopicQuery(topic));
      for (const auto& m : view) {
        const auto msg = m.instantiate<tf2_msgs::TFMessage>();
        if (!msg) continue;
        for (const auto& tf : msg->transforms) {
          const auto& t = tf.transform.translation;
          const auto& q = tf.transform.rotation;
          const double tv[3] = {t.x, t.y, t.z}, qv[4] = {q.x, q.y, q.z, q.w};
          poses_.add_transform(info_.path, topic, is_static, tf.header.frame_id, tf.child_frame_id,
                               to_seconds(tf.header.stamp), tv, qv);
        }
      }
    }
    if (!options_.odom_topic.empty()) {
      require_topic(types, options_.odom_topic, "nav_msgs/Odometry", "--odom-topic");
      rosbag::View view(bag_, rosbag::TopicQuery(options_.odom_topic));
      for (const auto& m : view) {
        const auto msg = m.instantiate<nav_msgs::Odometry>();
        if (!msg) continue;
        const auto& p = msg->pose.pose.position;
        const auto& q = msg->pose.pose.orientation;
        const double pv[3] = {p.x, p.y, p.z}, qv[4] = {q.x, q.y, q.z, q.w};
        poses_.add_odometry(info_.path, options_.odom_topic, to_seconds(msg->header.stamp), msg->header.frame_id,
                            msg->child_frame_id, pv, qv);
      }
    }
    poses_.resolve(info_, options_);
  }

  void pose_at(double t, std::size_t index, Eigen::Isometry3d& T_fixed_camera, Eigen::Isometry3d& T_fixed_base) const {
    poses_.pose_at(info_, options_, where(), t, index, T_fixed_camera, T_fixed_base);
  }

  const sensors::CameraIntrinsics& intrinsics_at(double t) const {
    auto it =
        std::upper_bound(infos_.begin(), infos_.end(), t, [](double time, const auto& s) { return time < s.first; });
    return it == infos_.begin() ? infos_.front().second : (it - 1)->second;
  }

  int bytes_per_pixel(const std::string& encoding) const { return depth_bytes_per_pixel(encoding, where()); }

  void decode(const sensor_msgs::Image& image, const sensors::CameraIntrinsics& k, sensors::DepthImage& out) const {
    ImageView view;
    view.encoding = image.encoding, view.width = image.width, view.height = image.height, view.step = image.step;
    view.is_bigendian = image.is_bigendian != 0, view.data = image.data.data(), view.size = image.data.size();
    decode_depth(view, k, info_.depth_unit_m, where() + ": frame " + std::to_string(index_), info_.info_topic, out);
  }

  RecordingOptions options_;
  RecordingInfo info_;
  rosbag::Bag bag_;
  std::unique_ptr<rosbag::View> view_;
  rosbag::View::iterator it_;
  bool started_ = false, done_ = false;
  std::size_t index_ = 0;
  std::vector<std::pair<double, sensors::CameraIntrinsics>> infos_;
  PoseResolver poses_;
};

}  // namespace

std::unique_ptr<Recording> open_bag(const std::string& path, const RecordingOptions& options) {
  return std::make_unique<BagRecording>(path, options);
}

RecordingContents list_bag(const std::string& path) {
  RecordingContents contents{path, "ros1 bag", {path}, {}, {}};
  try {
    rosbag::Bag bag;
    bag.open(path, rosbag::bagmode::Read);
    contents.topics = bag_topics(bag);
  } catch (const std::exception& e) {
    throw std::invalid_argument(path + ": cannot read the bag (truncated or corrupt?): " + e.what());
  }
  return contents;
}

}  // namespace stvl::recording::detail

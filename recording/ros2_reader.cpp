// rosbag2 recordings (MCAP or sqlite3) as frames: realsense-ros 4.x's layout (/camera/camera/depth/...), our
// export's, or any depth topic named; /tf, /tf_static or odometry for the poses (bag_common.hpp, as ROS 1). Only
// the topics read must decode; every other one is listed in info().topics, whatever its type and encodings.
#include <algorithm>
#include <cstdio>
#include <map>
#include <stdexcept>

#include "recording/bag_common.hpp"
#include "recording/detail.hpp"
#include "recording/ros2_msgs.hpp"
#include "recording/ros2_source.hpp"
#include "recording/ros2msg.hpp"

namespace stvl::recording::detail {
namespace {

bool ends_with(const std::string& text, const std::string& tail) {
  return text.size() >= tail.size() && text.compare(text.size() - tail.size(), tail.size(), tail) == 0;
}

// "its schema does not parse (line ...)" for a topic whose ros2msg schema does not, else "".
std::string schema_problem(const Ros2Topic& topic) {
  if (topic.schema_encoding != "ros2msg" || topic.type.empty()) return "";
  try {
    parse_ros2msg(topic.type, topic.schema);
  } catch (const MsgParseError& e) {
    return std::string("its schema does not parse (") + e.what() + ")";
  }
  return "";
}

class Ros2Recording final : public Recording {
 public:
  Ros2Recording(const std::string& path, const RecordingOptions& options) : options_(options), source_(path) {
    info_.path = path;
    info_.format = source_.format();
    info_.files = source_.files();
    for (const auto& w : source_.warnings()) std::fprintf(stderr, "warning: %s\n", w.c_str());
    open();
    cursor_ = source_.cursor(info_.depth_topic);
  }

  const RecordingInfo& info() const override { return info_; }

  bool next(RecordedFrame& frame) override {
    std::int64_t time_ns = 0;
    if (!cursor_->next(time_ns, bytes_)) return false;
    const std::string at = where() + ": frame " + std::to_string(index_);
    const ImageMsg image = decode_image(bytes_.data(), bytes_.size(), at);
    frame.index = index_;
    frame.stamp_s = image.stamp.seconds();
    frame.time_s = frame.stamp_s - info_.start_time_s;
    frame.intrinsics = intrinsics_at(frame.stamp_s);
    ImageView view;
    view.encoding = image.encoding, view.width = image.width, view.height = image.height, view.step = image.step;
    view.is_bigendian = image.is_bigendian, view.data = image.data, view.size = image.data_size;
    decode_depth(view, frame.intrinsics, info_.depth_unit_m, at, info_.info_topic, frame.depth);
    poses_.pose_at(info_, options_, where(), frame.stamp_s, index_, frame.T_fixed_camera, frame.T_fixed_base);
    ++index_;
    return true;
  }

 private:
  std::string where() const { return info_.path + ": " + info_.depth_topic; }

  void require_topic(const std::string& topic, const std::string& type, const char* option) const {
    const auto& topics = source_.topics();
    const auto it = topics.find(topic);
    if (it == topics.end()) {
      std::vector<std::string> same, all;
      for (const auto& [t, info] : topics) {
        all.push_back(t);
        if (short_type(info.type) == type) same.push_back(t);
      }
      const std::string near = nearest_name(topic, same.empty() ? all : same);
      throw std::invalid_argument(
          info_.path + ": no topic " + topic + " (" + option + ")" +
          (near.empty() ? std::string(", the recording has no topics") : ", nearest existing topic: " + near));
    }
    if (short_type(it->second.type) != type)
      throw std::invalid_argument(info_.path + ": topic " + topic + " is " + it->second.type + ", expected " + type);
  }

  void open() {
    choose_depth_topic();
    choose_info_topic();
    if (!options_.odom_topic.empty()) require_topic(options_.odom_topic, "nav_msgs/Odometry", "--odom-topic");
    choose_uses();

    // One pass: camera info, tf, odometry, and the depth frames' stamps.
    bool first = true;
    double last_stamp = 0;
    source_.scan(nullptr, [&](const Ros2Topic& t, std::int64_t, const std::uint8_t* data, std::size_t size) {
      read_message(t, data, size, first, last_stamp);
      return true;
    });
    if (info_.frame_count == 0) throw std::invalid_argument(where() + ": no depth images on the topic");
    if (infos_.empty()) throw std::invalid_argument(info_.path + ": " + info_.info_topic + " has no messages");
    std::stable_sort(infos_.begin(), infos_.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    info_.end_time_s = last_stamp;
    if (info_.frame_count > 1 && info_.end_time_s > info_.start_time_s) {
      const double rate_hz = (info_.frame_count - 1) / (info_.end_time_s - info_.start_time_s);
      for (auto& [t, k] : infos_) k.rate_hz = rate_hz;
    }
    info_.intrinsics = intrinsics_at(info_.start_time_s);
    poses_.resolve(info_, options_);
    Eigen::Isometry3d T_fixed_camera,
        T_fixed_base;  // the first frame's pose now: a recording without one fails at open
    poses_.pose_at(info_, options_, where(), info_.start_time_s, 0, T_fixed_camera, T_fixed_base);
  }

  // What each topic is read as; every topic read must decode (cdr, and a ros2msg schema with the fields decoded,
  // or none recorded); any other is listed, and a ros2msg schema of one that does not parse is a warning.
  void choose_uses() {
    uses_[info_.depth_topic] = "depth";
    uses_[info_.info_topic] = "camera_info";
    if (!options_.odom_topic.empty()) uses_[options_.odom_topic] = "odometry";
    for (const char* tf : {"/tf", "/tf_static"}) {
      const auto it = source_.topics().find(tf);
      if (it != source_.topics().end() && short_type(it->second.type) == "tf2_msgs/TFMessage" && !uses_.count(tf))
        uses_[tf] = tf + 1;
    }
    for (const auto& [name, topic] : source_.topics()) {
      TopicSummary summary{name, topic.type, topic.count, topic.message_encoding, topic.schema_encoding, "", ""};
      const auto use = uses_.find(name);
      if (use != uses_.end()) {
        summary.use = use->second;
        require_decodable(topic);
      } else {
        summary.note = skipped_note(topic);
      }
      info_.topics.push_back(summary);
    }
  }

  void require_decodable(const Ros2Topic& topic) const {
    const std::string where = info_.path + ": topic " + topic.name + " (" + uses_.at(topic.name) + ")";
    if (topic.message_encoding != "cdr")
      throw std::invalid_argument(where + ": message encoding '" + topic.message_encoding + "', expected cdr");
    if (topic.schema_encoding.empty()) return;  // no schema recorded (Humble's sqlite3): read by its type's name
    if (topic.schema_encoding != "ros2msg")
      throw std::invalid_argument(where + ": schema encoding '" + topic.schema_encoding +
                                  "' is not read (expected ros2msg)");
    check_ros2_schema(topic.type, topic.schema, where);
  }

  // Why a topic is not read, where that says more than its type (also printed as a warning).
  std::string skipped_note(const Ros2Topic& topic) const {
    const std::string note = schema_problem(topic);
    if (!note.empty())
      std::fprintf(stderr, "warning: %s: topic %s (%s, not read): %s\n", info_.path.c_str(), topic.name.c_str(),
                   topic.type.c_str(), note.c_str());
    return note;
  }

  // The depth topic: --depth-topic, else the only realsense-ros depth image topic.
  void choose_depth_topic() {
    const auto& topics = source_.topics();
    if (!options_.depth_topic.empty()) {
      require_topic(options_.depth_topic, "sensor_msgs/Image", "--depth-topic");
      info_.depth_topic = options_.depth_topic;
      return;
    }
    std::vector<std::string> names;
    for (const auto& [t, info] : topics)
      names.push_back(t + " (" + (info.type.empty() ? "no type" : info.type) + ", " + std::to_string(info.count) +
                      (info.count == 1 ? " message)" : " messages)"));
    std::vector<std::string> candidates;
    for (const auto& [t, info] : topics)
      if (short_type(info.type) == "sensor_msgs/Image" &&
          (ends_with(t, "/depth/image_rect_raw") || ends_with(t, "/aligned_depth_to_color/image_raw")))
        candidates.push_back(t);
    if (candidates.empty())
      throw std::invalid_argument(info_.path +
                                  ": no depth topic (looked for */depth/image_rect_raw, "
                                  "*/aligned_depth_to_color/image_raw; the recording has: " +
                                  join(names) + "); name one with --depth-topic");
    if (candidates.size() > 1)
      throw std::invalid_argument(info_.path + ": several depth topics: " + join(candidates) +
                                  "; choose one with --depth-topic");
    info_.depth_topic = candidates.front();
  }

  // The camera info: --info-topic, else camera_info beside the depth topic.
  void choose_info_topic() {
    const std::string& depth = info_.depth_topic;
    if (!options_.info_topic.empty()) {
      require_topic(options_.info_topic, "sensor_msgs/CameraInfo", "--info-topic");
      info_.info_topic = options_.info_topic;
      return;
    }
    info_.info_topic = depth.substr(0, depth.rfind('/')) + "/camera_info";
    if (!source_.topics().count(info_.info_topic))
      throw std::invalid_argument(info_.path + ": no camera info for " + depth + " (expected " + info_.info_topic +
                                  "); name one with --info-topic");
    require_topic(info_.info_topic, "sensor_msgs/CameraInfo", "camera info");
  }

  // open()'s pass over one message: a depth frame's stamp (the first's encoding, frame and stamp), camera info,
  // tf or odometry.
  void read_message(const Ros2Topic& t, const std::uint8_t* data, std::size_t size, bool& first, double& last_stamp) {
    const std::string what = info_.path + ": " + t.name;
    if (t.name == info_.depth_topic) {
      const ImageMsg image =
          decode_image(data, size, what + " (frame " + std::to_string(info_.frame_count) + ")", true);
      if (first) {
        info_.encoding = image.encoding;
        depth_bytes_per_pixel(image.encoding, where());
        info_.camera_frame = strip_slash(image.frame_id);
        info_.start_time_s = image.stamp.seconds();
        first = false;
      }
      last_stamp = image.stamp.seconds();
      ++info_.frame_count;
    } else if (t.name == info_.info_topic) {
      const CameraInfoMsg m = decode_camera_info(data, size, what);
      infos_.emplace_back(m.stamp.seconds(), make_intrinsics(m.width, m.height, m.k[0], m.k[4], m.k[2], m.k[5],
                                                             options_.rate_hz, options_, what + " k"));
    } else if (uses_.count(t.name) && (t.name == "/tf" || t.name == "/tf_static")) {
      for (const auto& tf : decode_tf(data, size, what))
        poses_.add_transform(info_.path, t.name, t.name == "/tf_static", tf.parent, tf.child, tf.stamp.seconds(), tf.t,
                             tf.q);
    } else if (t.name == options_.odom_topic) {
      const OdometryMsg m = decode_odometry(data, size, what);
      poses_.add_odometry(info_.path, t.name, m.stamp.seconds(), m.frame_id, m.child_frame_id, m.p, m.q);
    }
  }

  const sensors::CameraIntrinsics& intrinsics_at(double t) const {
    auto it =
        std::upper_bound(infos_.begin(), infos_.end(), t, [](double time, const auto& s) { return time < s.first; });
    return it == infos_.begin() ? infos_.front().second : (it - 1)->second;
  }

  RecordingOptions options_;
  RecordingInfo info_;
  Ros2Source source_;
  std::unique_ptr<Ros2Source::Cursor> cursor_;
  std::vector<std::uint8_t> bytes_;
  std::size_t index_ = 0;
  std::vector<std::pair<double, sensors::CameraIntrinsics>> infos_;
  PoseResolver poses_;
  std::map<std::string, std::string> uses_;  // topic -> what it is read as
};

}  // namespace

std::unique_ptr<Recording> open_ros2(const std::string& path, const RecordingOptions& options) {
  return std::make_unique<Ros2Recording>(path, options);
}

RecordingContents list_ros2(const std::string& path) {
  const Ros2Source source(path);
  RecordingContents contents{path, source.format(), source.files(), {}, source.warnings()};
  for (const auto& [name, t] : source.topics())
    contents.topics.push_back(
        TopicSummary{name, t.type, t.count, t.message_encoding, t.schema_encoding, "", schema_problem(t)});
  return contents;
}

}  // namespace stvl::recording::detail

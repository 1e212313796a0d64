#pragma once
// A run's bag, ROS 1 or rosbag2 (recording::BagSink), with the topics BagTopics chooses: per frame the robot's topics
// (once per distinct time) and the frame's camera's topics, every publish period (and at the end) the STVL map and
// costmap. Messages are packed on the frame loop's thread and written on a thread of their own. A replayed recording
// writes the same topics but the ground truth's (it has none).
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "layer/layer.hpp"
#include "pipeline/config.hpp"
#include "pipeline/frame.hpp"
#include "recording/bag_writer.hpp"

namespace stvl {
class SerialWorker;
}  // namespace stvl

namespace stvl::run {

using recording::BagCompression;
using recording::BagSink;
using recording::BagWriter;
using recording::parse_bag_compression;

// Format, compression and topics of a bag from the options' strings (their defaults per format); throws
// std::invalid_argument for a bad name.
struct BagSettings {
  recording::BagFormat format = recording::BagFormat::kRos1;
  BagCompression compression = BagCompression::kNone;
  std::string topics = "all";
};
BagSettings bag_settings(const std::string& path, const std::string& format, const std::string& compression,
                         const std::string& topics);

// The topic of a source's marking clouds: /stvl/filtered_points when the config has one source, else
// /stvl/<source>/filtered_points (a native camera's one source is named after the camera).
std::string source_cloud_topic(const std::vector<pipeline::CameraConfig>& cameras, std::size_t camera_index,
                               std::size_t source_index);

// The cameras' frames on base_link as the simulated robot mounts them (camera_link, then its optical frame).
std::vector<BagSink::CameraFrames> camera_frames(const std::vector<pipeline::CameraConfig>& cameras);

class BagRecorder {
 public:
  // Opens path (as path.active until close()) and writes /tf_static for the cameras and, with ground truth, its
  // latched occupancy; without (truth == nullptr) no /ground_truth topic is written.
  BagRecorder(const std::string& path, const BagSettings& settings, const std::vector<BagSink::CameraFrames>& cameras,
              const Eigen::Matrix3Xf* truth_voxel_centers_W);
  ~BagRecorder();  // without close(): the bag stays as path.active
  BagRecorder(const BagRecorder&) = delete;
  BagRecorder& operator=(const BagRecorder&) = delete;

  // The map and the costmap it projects to.
  struct MapState {
    const mapping::VoxelMap* map = nullptr;
    std::function<mapping::Costmap2D()> costmap;
    // The costmap exists without voxels (nav2's layers: their window); STVL's has none while the map is empty.
    bool costmap_without_voxels = false;
    bool has_costmap() const { return costmap_without_voxels || !map->empty(); }
  };
  // The frame's messages (its camera's intrinsics, from cameras[frame.camera_index]; topics per camera when there
  // are several); for the layer's updates of the frame (report), the readings they took (source_cloud_topic(),
  // stamped with the reading's time, recorded at the update's: only those, each as often as an update applied it);
  // the map and costmap too when publish_map.
  void record(const pipeline::Frame& frame, const layer::UpdateReport& report,
              const std::vector<pipeline::CameraConfig>& cameras, const MapState& map, bool publish_map);
  // A closed loop's messages as nav2 publishes them (navigation2 jazzy): the controller's twists on /cmd_vel at
  // their ticks, the global plans on /plan at their planning cycles, the costmaps on /local_costmap/costmap and
  // /global_costmap/costmap at their publish times. Each at its own time (all before the frame that follows).
  struct NavigationMessages {
    std::vector<std::pair<double, Eigen::Vector2d>> twists;              // (t_s, (v_mps, omega_radps))
    std::vector<std::pair<double, std::vector<Eigen::Vector3d>>> plans;  // (t_s, poses x, y, yaw)
    std::vector<std::pair<double, mapping::Costmap2D>> local, global;    // (t_s, costmap)
  };
  void record_navigation(NavigationMessages messages);
  // The map and costmap once more at time_s (the end of the run).
  void record_map(double time_s, const MapState& map);
  // Waits for the writer thread, writes the index and renames path.active to path.
  void close();
  // The export's final path (a rosbag2 folder for ROS 2) and its size so far in bytes.
  const std::string& path() const { return bag_->path(); }
  std::uint64_t bytes_written() const { return bag_->bytes_written(); }

 private:
  std::unique_ptr<BagSink> bag_;
  recording::BagTopics topics_;
  std::unique_ptr<SerialWorker> worker_;  // declared after the bag: stops first
  std::optional<double> last_robot_time_s_;
  bool ground_truth_ = true;
};

}  // namespace stvl::run

#pragma once
// A run's ROS 1 bag: per frame the robot's topics (once per distinct time) and the frame's camera's topics, every publish period (and at the end) the
// STVL map and costmap. Messages are packed on the frame loop's thread and written on a thread of their own.
// A replayed recording writes the same topics but the ground truth's (it has none).
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "pipeline/pipeline.hpp"
#include "recording/bag_writer.hpp"

namespace stvl {
class SerialWorker;
}  // namespace stvl

namespace stvl::run {

using recording::BagCompression;
using recording::BagWriter;
using recording::parse_bag_compression;

class BagRecorder {
 public:
  // Opens path (as path.active until close()) and writes /tf_static for the cameras and, with ground truth, its
  // latched occupancy; without (truth == nullptr) no /ground_truth topic is written.
  BagRecorder(const std::string& path, BagCompression compression, const std::vector<BagWriter::CameraFrames>& cameras,
              const Eigen::Matrix3Xf* truth_voxel_centers_W);
  // A simulated run: the pipeline's cameras and the truth.
  BagRecorder(const std::string& path, BagCompression compression, const pipeline::Pipeline& pipeline,
              const Eigen::Matrix3Xf& truth_voxel_centers_W);
  ~BagRecorder();  // without close(): the bag stays as path.active
  BagRecorder(const BagRecorder&) = delete;
  BagRecorder& operator=(const BagRecorder&) = delete;

  // The map and the costmap it projects to.
  struct MapState {
    const mapping::VoxelMap* map = nullptr;
    std::function<mapping::Costmap2D()> costmap;
  };
  // The frame's messages (its camera's intrinsics; topics per camera when there are several); the map and
  // costmap too when publish_map.
  void record(const pipeline::FrameResult& frame, const sensors::CameraIntrinsics& intrinsics, bool several_cameras,
              const MapState& map, bool publish_map);
  void record(const pipeline::FrameResult& frame, const pipeline::Pipeline& pipeline, bool publish_map);
  // The map and costmap once more at time_s (the end of the run).
  void record_map(double time_s, const MapState& map);
  void record_map(double time_s, const pipeline::Pipeline& pipeline);
  // Waits for the writer thread, writes the index and renames path.active to path.
  void close();

 private:
  std::unique_ptr<BagWriter> bag_;
  std::unique_ptr<SerialWorker> worker_;  // declared after the bag: stops first
  std::optional<double> last_robot_time_s_;
  bool ground_truth_ = true;
};

}  // namespace stvl::run

#pragma once
// A run's ROS 1 bag: per frame the robot's topics (once per distinct time) and the frame's camera's topics, every publish period (and at the end) the
// STVL map and costmap. Messages are packed on the frame loop's thread and written on a thread of their own.
#include <memory>
#include <optional>
#include <string>

#include "pipeline/pipeline.hpp"
#include "tools/bag_writer.hpp"

namespace stvl::tools {

class SerialWorker;

class BagRecorder {
 public:
  // Opens path (as path.active until close()) and writes /tf_static and the latched ground-truth occupancy.
  BagRecorder(const std::string& path, BagCompression compression, const pipeline::Pipeline& pipeline,
              const Eigen::Matrix3Xf& truth_voxel_centers_W);
  ~BagRecorder();  // without close(): the bag stays as path.active
  BagRecorder(const BagRecorder&) = delete;
  BagRecorder& operator=(const BagRecorder&) = delete;

  // The frame's messages; the map and costmap (as the pipeline projects them) too when publish_map.
  void record(const pipeline::FrameResult& frame, const pipeline::Pipeline& pipeline, bool publish_map);
  // The map and costmap once more at time_s (the end of the run).
  void record_map(double time_s, const pipeline::Pipeline& pipeline);
  // Waits for the writer thread, writes the index and renames path.active to path.
  void close();

 private:
  std::unique_ptr<BagWriter> bag_;
  std::unique_ptr<SerialWorker> worker_;  // declared after the bag: stops first
  std::optional<double> last_robot_time_s_;
};

}  // namespace stvl::tools

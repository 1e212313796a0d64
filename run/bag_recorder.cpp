#include "run/bag_recorder.hpp"

#include <optional>

#include "common/serial_worker.hpp"

namespace stvl::run {
namespace {

using recording::camera_optical_frame;
using recording::camera_topic;
using recording::kMapFrame;

std::vector<BagWriter::CameraFrames> camera_frames(const pipeline::Pipeline& pipeline) {
  std::vector<BagWriter::CameraFrames> frames;
  for (const auto& c : pipeline.config().cameras)
    frames.push_back({c.name, sim::T_base_camera_link(c.mount), sim::DiffDriveRobot::T_camera_link_optical()});
  return frames;
}

BagRecorder::MapState map_state(const pipeline::Pipeline& pipeline) {
  return {&pipeline.map(), [&pipeline] { return pipeline.costmap(); }};
}

}  // namespace

BagRecorder::BagRecorder(const std::string& path, BagCompression compression,
                         const std::vector<BagWriter::CameraFrames>& cameras, const Eigen::Matrix3Xf* truth_voxel_centers_W)
    : bag_(std::make_unique<BagWriter>(path, compression)), worker_(std::make_unique<SerialWorker>()),
      ground_truth_(truth_voxel_centers_W != nullptr) {
  bag_->write_tf_static(cameras);
  if (truth_voxel_centers_W) bag_->write_points("/ground_truth/occupancy", 0.0, kMapFrame, *truth_voxel_centers_W, true);
}

BagRecorder::BagRecorder(const std::string& path, BagCompression compression, const pipeline::Pipeline& pipeline,
                         const Eigen::Matrix3Xf& truth_voxel_centers_W)
    : BagRecorder(path, compression, camera_frames(pipeline), &truth_voxel_centers_W) {}

BagRecorder::~BagRecorder() = default;

void BagRecorder::record(const pipeline::FrameResult& f, const pipeline::Pipeline& pipeline, bool publish_map) {
  record(f, pipeline.config().cameras[f.camera_index].intrinsics, pipeline.config().cameras.size() > 1,
         map_state(pipeline), publish_map);
}

void BagRecorder::record(const pipeline::FrameResult& f, const sensors::CameraIntrinsics& intrinsics,
                         bool several_cameras, const MapState& map, bool publish_map) {
  std::optional<mapping::Costmap2D> costmap;
  Eigen::Matrix3Xf voxels;
  if (publish_map) {
    voxels = map.map->voxel_centers();
    if (!map.map->empty()) costmap = map.costmap();
  }
  const std::string& camera = f.camera;
  // One camera: /stvl/filtered_points; several: /stvl/<camera>/filtered_points (frames of one time would
  // otherwise share a topic and a stamp).
  const std::string filtered_topic = several_cameras ? "/stvl/" + camera + "/filtered_points" : "/stvl/filtered_points";
  // Cameras whose frames share a time share its robot messages (tf would warn of repeated data).
  const bool robot_messages = !last_robot_time_s_ || f.time_s > *last_robot_time_s_;
  last_robot_time_s_ = f.time_s;
  // The lambda copies what each message needs; the frame is overwritten by the next step().
  worker_->submit([bag = bag_.get(), t = f.time_s, T_world_base = f.T_world_base, T_map_odom = f.T_map_odom,
                   T_odom_base = f.T_odom_base, v = f.odom_v_mps, omega = f.odom_omega_radps, intrinsics, camera, filtered_topic,
                   depth = f.depth, cloud_C = Eigen::Matrix3Xf(f.cloud_C()), marking_W = f.marking_W,
                   voxels = std::move(voxels), publish_map, costmap = std::move(costmap), robot_messages,
                   ground_truth = ground_truth_] {
    if (robot_messages) {
      bag->write_clock(t);
      bag->write_tf(t, T_map_odom, T_odom_base);
      bag->write_odometry(t, T_odom_base, v, omega);
      if (ground_truth) bag->write_ground_truth_pose(t, T_world_base);
    }
    bag->write_depth_image(t, intrinsics, sensors::depth_to_millimetres(depth), camera);
    bag->write_camera_info(t, intrinsics, camera);
    bag->write_points(camera_topic(camera, "depth/points"), t, camera_optical_frame(camera), cloud_C);
    bag->write_points(filtered_topic, t, kMapFrame, marking_W);
    if (publish_map) bag->write_points("/stvl/voxel_grid", t, kMapFrame, voxels);
    if (costmap) bag->write_costmap(t, *costmap);
  });
}

void BagRecorder::record_map(double time_s, const pipeline::Pipeline& pipeline) { record_map(time_s, map_state(pipeline)); }

void BagRecorder::record_map(double time_s, const MapState& map) {
  std::optional<mapping::Costmap2D> costmap;
  if (!map.map->empty()) costmap = map.costmap();
  worker_->submit([bag = bag_.get(), time_s, voxels = map.map->voxel_centers(), costmap = std::move(costmap)] {
    bag->write_points("/stvl/voxel_grid", time_s, kMapFrame, voxels);
    if (costmap) bag->write_costmap(time_s, *costmap);
  });
}

void BagRecorder::close() {
  worker_->finish();
  bag_->close();
}

}  // namespace stvl::run

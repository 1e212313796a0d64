#include "run/bag_recorder.hpp"

#include <optional>

#include "common/serial_worker.hpp"

namespace stvl::run {
namespace {

using recording::camera_optical_frame;
using recording::camera_topic;
using recording::kMapFrame;

}  // namespace

BagSettings bag_settings(const std::string& path, const std::string& format, const std::string& compression,
                         const std::string& topics) {
  BagSettings s;
  s.format = recording::parse_bag_format(format, path);
  const bool ros2 = s.format == recording::BagFormat::kRos2;
  s.compression = parse_bag_compression(compression.empty() ? (ros2 ? "zstd" : "none") : compression);
  s.topics = topics.empty() ? (ros2 ? "default" : "all") : topics;
  recording::BagTopics check(s.topics);  // a bad entry fails before the run starts
  return s;
}

BagRecorder::BagRecorder(const std::string& path, const BagSettings& settings,
                         const std::vector<BagSink::CameraFrames>& cameras,
                         const Eigen::Matrix3Xf* truth_voxel_centers_W)
    : bag_(recording::make_bag_writer(path, settings.format, settings.compression)),
      topics_(settings.topics),
      worker_(std::make_unique<SerialWorker>()),
      ground_truth_(truth_voxel_centers_W != nullptr) {
  if (topics_.wants("/tf_static")) bag_->write_tf_static(cameras);
  if (truth_voxel_centers_W && topics_.wants("/ground_truth/occupancy"))
    bag_->write_points("/ground_truth/occupancy", 0.0, kMapFrame, *truth_voxel_centers_W, true);
}

std::vector<BagSink::CameraFrames> camera_frames(const std::vector<pipeline::CameraConfig>& cameras) {
  std::vector<BagSink::CameraFrames> frames;
  for (const auto& c : cameras)
    frames.push_back({c.name, sim::T_base_camera_link(c.mount), sim::DiffDriveRobot::T_camera_link_optical()});
  return frames;
}

BagRecorder::~BagRecorder() = default;

std::string source_cloud_topic(const std::vector<pipeline::CameraConfig>& cameras, std::size_t camera_index,
                               std::size_t source_index) {
  std::size_t sources = 0;
  for (const auto& c : cameras) sources += c.sources.size();
  if (sources <= 1) return "/stvl/filtered_points";
  return "/stvl/" + cameras.at(camera_index).sources.at(source_index).name + "/filtered_points";
}

void BagRecorder::record(const pipeline::Frame& f, const layer::UpdateReport& report,
                         const std::vector<pipeline::CameraConfig>& cameras, const MapState& map, bool publish_map) {
  const sensors::CameraIntrinsics& intrinsics = cameras.at(f.camera_index).intrinsics;
  std::optional<mapping::Costmap2D> costmap;
  Eigen::Matrix3Xf voxels;
  const bool want_voxels = publish_map && topics_.wants("/stvl/voxel_grid");
  if (want_voxels) voxels = map.map->voxel_centers();
  if (publish_map && map.has_costmap() && topics_.wants("/stvl/costmap")) costmap = map.costmap();
  const std::string& camera = f.camera;
  // The update's readings, as STVL's Mark and ClearFrustums would take them: topic, header stamp, cloud.
  // Recorded at the update's time: an update at an earlier tick (map.update_frequency) goes before this frame.
  struct Reading {
    std::string topic;
    double update_s, stamp_s;
    Eigen::Matrix3Xf points_W;
  };
  std::vector<Reading> readings;
  for (const auto& update : report.updates)
    for (const auto& applied : update.applied_readings) {
      const std::string topic = source_cloud_topic(cameras, applied.sensor_index, applied.source_index);
      if (!topics_.wants(topic)) continue;
      const auto& source = cameras.at(applied.sensor_index).sources.at(applied.source_index).params;
      readings.push_back({topic, update.time_s, applied.reading->header_stamp_s(),
                          applied.cloud_W ? *applied.cloud_W : layer::source_marking_W(*applied.reading, source)});
    }
  // Cameras whose frames share a time share its robot messages (tf would warn of repeated data). With camera timing
  // the robot's messages are odometry's, at their stamps, as they reached tf.
  const bool robot_messages = !f.tf_from_messages && (!last_robot_time_s_ || f.time_s > *last_robot_time_s_);
  last_robot_time_s_ = f.time_s;
  // The lambda copies what each message needs; the frame is overwritten by the next step().
  const recording::BagTopics& w = topics_;
  const bool want[] = {w.wants("/clock"),
                       w.wants("/tf"),
                       w.wants("/odom"),
                       w.wants("/ground_truth/pose"),
                       w.wants(camera_topic(camera, "depth/image_rect_raw")),
                       w.wants(camera_topic(camera, "depth/camera_info")),
                       w.wants(camera_topic(camera, "depth/points"))};
  worker_->submit([bag = bag_.get(), want = std::vector<bool>(std::begin(want), std::end(want)), t = f.time_s,
                   stamp = f.stamp_s, T_world_base = f.T_world_base, T_map_odom = f.T_map_odom,
                   T_odom_base = f.T_odom_base, v = f.odom_v_mps, omega = f.odom_omega_radps, intrinsics, camera,
                   depth = f.depth, cloud_C = want[6] ? Eigen::Matrix3Xf(f.cloud_C()) : Eigen::Matrix3Xf(),
                   readings = std::move(readings), voxels = std::move(voxels), want_voxels, messages = f.odom_messages,
                   costmap = std::move(costmap), robot_messages, ground_truth = ground_truth_] {
    for (const auto& r : readings)
      if (r.update_s < t) bag->write_points_stamped(r.topic, r.update_s, r.stamp_s, kMapFrame, r.points_W);
    for (const pipeline::OdomMessage& m : messages) {
      if (want[0]) bag->write_clock(m.stamp_s);
      if (want[1]) bag->write_tf(m.stamp_s, m.T_map_odom, m.T_odom_base);
      if (want[2]) bag->write_odometry(m.stamp_s, m.T_odom_base, m.v_mps, m.omega_radps);
      if (ground_truth && want[3]) bag->write_ground_truth_pose(m.stamp_s, m.T_world_base);
    }
    if (robot_messages) {
      if (want[0]) bag->write_clock(t);
      if (want[1]) bag->write_tf(t, T_map_odom, T_odom_base);
      if (want[2]) bag->write_odometry(t, T_odom_base, v, omega);
      if (ground_truth && want[3]) bag->write_ground_truth_pose(t, T_world_base);
    }
    // The camera's messages with the stamp its driver wrote, recorded when they reached the layer.
    if (want[4]) bag->write_depth_image_stamped(t, stamp, intrinsics, sensors::depth_to_millimetres(depth), camera);
    if (want[5]) bag->write_camera_info_stamped(t, stamp, intrinsics, camera);
    if (want[6])
      bag->write_points_stamped(camera_topic(camera, "depth/points"), t, stamp, camera_optical_frame(camera), cloud_C);
    for (const auto& r : readings)
      if (r.update_s >= t) bag->write_points_stamped(r.topic, t, r.stamp_s, kMapFrame, r.points_W);
    if (want_voxels) bag->write_points("/stvl/voxel_grid", t, kMapFrame, voxels);
    if (costmap) bag->write_costmap(t, *costmap);
  });
}

void BagRecorder::record_navigation(NavigationMessages m) {
  const recording::BagTopics& w = topics_;
  if (!w.wants(recording::kCmdVelTopic)) m.twists.clear();
  if (!w.wants(recording::kPlanTopic)) m.plans.clear();
  if (!w.wants(recording::kLocalCostmapTopic)) m.local.clear();
  if (!w.wants(recording::kGlobalCostmapTopic)) m.global.clear();
  worker_->submit([bag = bag_.get(), m = std::move(m)] {
    for (const auto& [t, twist] : m.twists) bag->write_twist(recording::kCmdVelTopic, t, twist.x(), twist.y());
    for (const auto& [t, poses] : m.plans) bag->write_path(recording::kPlanTopic, t, poses);
    for (const auto& [t, costmap] : m.local) bag->write_costmap_on(recording::kLocalCostmapTopic, t, costmap);
    for (const auto& [t, costmap] : m.global) bag->write_costmap_on(recording::kGlobalCostmapTopic, t, costmap);
  });
}

void BagRecorder::record_map(double time_s, const MapState& map) {
  std::optional<mapping::Costmap2D> costmap;
  if (map.has_costmap() && topics_.wants("/stvl/costmap")) costmap = map.costmap();
  const bool want_voxels = topics_.wants("/stvl/voxel_grid");
  worker_->submit([bag = bag_.get(), time_s, want_voxels,
                   voxels = want_voxels ? map.map->voxel_centers() : Eigen::Matrix3Xf(), costmap = std::move(costmap)] {
    if (want_voxels) bag->write_points("/stvl/voxel_grid", time_s, kMapFrame, voxels);
    if (costmap) bag->write_costmap(time_s, *costmap);
  });
}

void BagRecorder::close() {
  worker_->finish();
  bag_->close();
}

}  // namespace stvl::run

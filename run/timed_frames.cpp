#include "run/timed_frames.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

#include "common/splitmix.hpp"
#include "common/units.hpp"

namespace stvl::run {
namespace {

void transform_in_place(const Eigen::Isometry3f& T, Eigen::Matrix3Xf& points) {
  if (points.cols() == 0) return;
  points = (T.linear() * points).colwise() + T.translation();
}

// An observation's clouds and camera moved rigidly to the camera pose T_world_camera.
void place(layer::Observation& o, const Eigen::Isometry3d& T_world_camera) {
  const Eigen::Isometry3f correction = (T_world_camera * o.T_world_camera.inverse()).cast<float>();
  transform_in_place(correction, o.decimated_W);
  transform_in_place(correction, o.marking_W);
  transform_in_place(correction, o.no_return_W);
  o.T_world_camera = T_world_camera;
}

}  // namespace

TimedFrames::TimedFrames(FrameSource& inner, pipeline::Pipeline& pipeline, std::uint64_t seed, double duration_s,
                         bool map_copy)
    : inner_(inner),
      pipeline_(pipeline),
      seed_(seed),
      duration_s_(duration_s),
      map_copy_(map_copy),
      tf_(pipeline.config().tf),
      stats_(pipeline.config().cameras.size()),
      queued_(pipeline.config().cameras.size()) {}

void TimedFrames::record_poses_until(double time_s) {
  const double period_s = 1.0 / tf_.odom_rate_hz;
  for (double t = messages_.size() * period_s; t <= time_s + kTimeEpsilon_s; t = messages_.size() * period_s) {
    pipeline_.run_until(t);
    const sim::Simulator& sim = pipeline_.simulator();
    messages_.push_back({t, sim.T_world_base(), sim.T_odom_base(), sim.T_map_odom(), sim.odometry().v_mps(),
                         sim.odometry().omega_radps()});
  }
}

LocalizationStats TimedFrames::localization() const {
  LocalizationStats stats = localization_;
  const sim::Simulator& sim = pipeline_.simulator();
  stats.corrections = sim.corrections().size();
  if (stats.corrections == 0) return stats;
  for (const sim::LocalizationJump& j : pipeline_.config().sim.localization.jumps)
    stats.jumps += j.at_s <= sim.corrections().back().time_s + 1e-9;
  return stats;
}

Eigen::Isometry3d TimedFrames::pose_at(Eigen::Isometry3d pipeline::OdomMessage::*pose, double stamp_s) const {
  const double at = std::max(0.0, stamp_s) * tf_.odom_rate_hz;
  const std::size_t k0 = std::min(static_cast<std::size_t>(std::floor(at + 1e-9)), messages_.size() - 1);
  const double f = std::clamp(at - static_cast<double>(k0), 0.0, 1.0);
  if (f < 1e-9 || k0 + 1 >= messages_.size()) return messages_[k0].*pose;
  // tf2's interpolation: translation linear, rotation slerp.
  const Eigen::Isometry3d &a = messages_[k0].*pose, &b = messages_[k0 + 1].*pose;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(a.linear()).slerp(f, Eigen::Quaterniond(b.linear())).toRotationMatrix();
  T.translation() = (1.0 - f) * a.translation() + f * b.translation();
  return T;
}

bool TimedFrames::capture() {
  if (pipeline_.next_time_s() > duration_s_ + kTimeEpsilon_s) return false;
  record_poses_until(pipeline_.next_time_s());  // the odometry messages before this capture
  const pipeline::Frame* f = inner_.next();
  if (!f) return false;
  if (!f->robot_upright) {
    passthrough_ = f;
    return true;
  }
  const std::size_t c = f->camera_index;
  const sensors::CameraTimingConfig& timing = cameras().at(c).timing;
  CameraTimingStats& stats = stats_[c];
  ++stats.captured;
  const sensors::FrameTiming t =
      sensors::frame_timing(timing, splitmix64(seed_ ^ (0x7173ull + c)), f->frame_index, f->time_s);
  if (t.dropped) {
    ++stats.dropped[layer::to_string(layer::DropReason::kCamera)];
    events_.push_back({c, f->time_s, -1, layer::to_string(layer::DropReason::kCamera)});
    lost(*f, f->time_s);
    return true;
  }
  const layer::FilterVerdict verdict = layer::message_filter(tf_, t.arrival_s, t.stamp_s);
  if (!verdict.delivered()) {
    ++stats.dropped[layer::to_string(verdict.reason)];
    events_.push_back({c, f->time_s, -1, layer::to_string(verdict.reason)});
    lost(*f, f->time_s);
    return true;
  }
  // The filter's queue: readings of this camera still waiting for their transform when this one arrives; at
  // queue_size the oldest waiting is dropped (tf2_ros::MessageFilter::add).
  std::deque<double>& waiting = queued_[c];
  while (!waiting.empty() && waiting.front() <= t.arrival_s) waiting.pop_front();
  if (waiting.size() >= tf_.queue_size) {
    const double oldest = waiting.front();
    waiting.pop_front();
    const auto it = std::find_if(pending_.begin(), pending_.end(), [&](const Pending& p) {
      return p.frame.camera_index == c && p.delivered_s == oldest;
    });
    if (it != pending_.end()) {
      events_.push_back({c, it->capture_s, -1, layer::to_string(layer::DropReason::kQueueFull)});
      lost(it->frame, f->time_s);
      pending_.erase(it);
    }
    ++stats.dropped[layer::to_string(layer::DropReason::kQueueFull)];
  }
  if (verdict.delivered_s > t.arrival_s) waiting.push_back(verdict.delivered_s);
  Pending p;
  p.frame = *f;
  p.capture_s = f->time_s, p.stamp_s = t.stamp_s, p.delivered_s = verdict.delivered_s, p.order = order_++;
  const auto at = std::upper_bound(pending_.begin(), pending_.end(), p, [](const Pending& a, const Pending& b) {
    return a.delivered_s < b.delivered_s || (a.delivered_s == b.delivered_s && a.order < b.order);
  });
  pending_.insert(at, std::move(p));
  return true;
}

void TimedFrames::deliver(Pending& p) {
  record_poses_until(p.delivered_s);
  pipeline_.run_until(p.delivered_s);
  out_ = std::move(p.frame);
  pipeline::Frame& f = out_;
  layer::Observation& o = *f.observation;
  // The cloud was placed with the camera's true pose at capture; tf places it with the robot's pose at the stamp: in
  // map with localization, the correction in force then composed with odometry.
  const sim::LocalizationConfig& loc = pipeline_.config().sim.localization;
  const sim::Simulator& sim = pipeline_.simulator();
  const Eigen::Isometry3d T_base_camera = f.T_world_base.inverse() * o.T_world_camera;
  const Eigen::Isometry3d T_world_base_stamp = pose_at(&pipeline::OdomMessage::T_world_base, p.stamp_s);
  Eigen::Isometry3d T_placed_base = T_world_base_stamp, T_map_base = T_world_base_stamp;
  const bool layer_in_odom = loc.layer_in_odom || map_copy_;  // closed loop: the run's layer is the local costmap's
  std::shared_ptr<layer::Observation> in_map;                 // closed loop: the global costmap's copy, in map
  if (loc.enabled) {
    T_map_base = sim.T_map_odom_at(p.stamp_s) * pose_at(&pipeline::OdomMessage::T_odom_base, p.stamp_s);
    if (!layer_in_odom) T_placed_base = T_map_base;
    if (map_copy_) in_map = std::make_shared<layer::Observation>(o);
    const Eigen::Isometry3d error = T_world_base_stamp.inverse() * T_map_base;
    const double error_m = (T_map_base.translation() - T_world_base_stamp.translation()).head<2>().norm();
    const double error_yaw = std::abs(Eigen::AngleAxisd(error.linear()).angle());
    LocalizationStats& ls = localization_;
    ++ls.readings;
    ls.mean_error_m += (error_m - ls.mean_error_m) / static_cast<double>(ls.readings);
    ls.mean_error_yaw_rad += (error_yaw - ls.mean_error_yaw_rad) / static_cast<double>(ls.readings);
    ls.max_error_m = std::max(ls.max_error_m, error_m);
    ls.max_error_yaw_rad = std::max(ls.max_error_yaw_rad, error_yaw);
  }
  place(o, T_placed_base * T_base_camera);
  // The layer takes it now: its clock (decay, ticks, staleness) and the robot's pose now (footprint clearing).
  o.time_s = p.delivered_s;
  o.stamp_s = p.stamp_s;
  o.T_world_base = loc.enabled && !layer_in_odom ? sim.T_map_base() : sim.T_world_base();
  if (in_map) {
    place(*in_map, T_map_base * T_base_camera);
    in_map->time_s = p.delivered_s;
    in_map->stamp_s = p.stamp_s;
    in_map->T_world_base = sim.T_map_base();
  }
  f.observation_map = std::move(in_map);
  f.time_s = p.delivered_s;
  f.stamp_s = p.stamp_s;      // the bag keeps the stamp as given, recorded at delivery
  f.tf_from_messages = true;  // and tf as it reached the buffer: the odometry messages arrived by now
  f.odom_messages.clear();
  for (; messages_sent_ < messages_.size() &&
         messages_[messages_sent_].stamp_s + tf_.odom_latency_s <= p.delivered_s + kTimeEpsilon_s;
       ++messages_sent_)
    f.odom_messages.push_back(messages_[messages_sent_]);
  f.T_world_base = sim.T_world_base();
  f.world = &sim.world();  // the evaluation and the stop at the path's end judge the world at delivery
  f.path_finished = sim.path_finished();
  f.laps_completed = sim.laps_completed();
  // tf now, for the bag: odometry, and map -> odom as the localizer publishes it.
  f.T_odom_base = sim.T_odom_base();
  f.T_map_odom = sim.T_map_odom();
  for (std::size_t c = 0; c < f.cameras_now.size(); ++c) {
    f.cameras_now[c].T_world_camera = sim.T_world_camera(cameras()[c].mount);
    f.cameras_now[c].next_frame_time_s += cameras()[c].timing.latency_mean_s;  // its next frame's expected arrival
  }
  events_.push_back({f.camera_index, p.capture_s, p.delivered_s, "delivered"});
  CameraTimingStats& stats = stats_[f.camera_index];
  const double delay_s = p.delivered_s - p.capture_s, stamp_error_s = std::abs(p.stamp_s - p.capture_s);
  ++stats.delivered;
  const double n = static_cast<double>(stats.delivered);
  stats.mean_delay_s += (delay_s - stats.mean_delay_s) / n;
  stats.max_delay_s = std::max(stats.max_delay_s, delay_s);
  stats.mean_stamp_error_s += (stamp_error_s - stats.mean_stamp_error_s) / n;
  stats.max_stamp_error_s = std::max(stats.max_stamp_error_s, stamp_error_s);
}

const pipeline::Frame* TimedFrames::next() {
  while (true) {
    if (passthrough_) {
      const pipeline::Frame* f = passthrough_;
      passthrough_ = nullptr;
      return f;
    }
    const double next_capture_s = inner_done_ ? std::numeric_limits<double>::infinity() : pipeline_.next_time_s();
    // A pending reading goes when no later capture can be delivered before it (latencies are >= 0).
    if (!pending_.empty() && pending_.front().delivered_s <= next_capture_s) {
      Pending p = std::move(pending_.front());
      pending_.erase(pending_.begin());
      if (p.delivered_s > duration_s_ + kTimeEpsilon_s) {
        ++stats_[p.frame.camera_index].after_end;
        events_.push_back({p.frame.camera_index, p.capture_s, -1, "after_end"});
        continue;
      }
      deliver(p);
      return &out_;
    }
    if (inner_done_) return nullptr;
    if (!capture()) inner_done_ = true;
  }
}

}  // namespace stvl::run

#include "sim/simulator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace stvl::sim {

Simulator::Simulator(World world, SimulatorConfig config)
    : world_(std::move(world)),
      config_(std::move(config)),
      robot_(world_, config_.robot),
      follower_(config_.follower),
      odometry_(robot_.wheel_radius_m(), robot_.track_width_m(), config_.odometry) {
  if (!(config_.control_period_s > 0)) {
    throw std::invalid_argument("control_period_s " + std::to_string(config_.control_period_s) + " must be > 0");
  }
  steps_per_control_ = std::max(1, static_cast<int>(std::lround(config_.control_period_s / world_.timestep_s())));
  robot_.set_camera_mount(config_.camera_mount);
  if (config_.drive == DriveMode::kAuto) throw std::invalid_argument("simulator: drive auto must be resolved first");
  if (config_.drive == DriveMode::kKinematic) {
    kinematic_.emplace(config_.follower);
    const Eigen::Isometry3d T = robot_.T_world_base();
    hold_ = {T.translation().x(), T.translation().y(), std::atan2(T.linear()(1, 0), T.linear()(0, 0))};
    // Placed, not pushed: the robot's geoms touch nothing (no contact forces on the world, no unstable wheels).
    mjModel* m = world_.mutable_model();
    for (int g = 0; g < m->ngeom; ++g)
      for (int b = m->geom_bodyid[g]; b > 0; b = m->body_parentid[b])
        if (b == robot_.base_body_id()) {
          m->geom_contype[g] = m->geom_conaffinity[g] = 0;
          break;
        }
  }
}

void Simulator::set_start_pose(const Pose2D& pose_W) {
  robot_.set_pose(pose_W.x_m, pose_W.y_m, pose_W.yaw_rad);
  hold_ = pose_W;
  odometry_ = WheelOdometry(robot_.wheel_radius_m(), robot_.track_width_m(), config_.odometry);
  corrections_.clear();
  if (config_.localization.enabled) publish_corrections();  // correction 0, at the start
}

Eigen::Isometry3d Simulator::T_map_odom() const {
  if (corrections_.empty()) return T_world_base() * T_odom_base().inverse();
  return corrections_.back().T_map_odom;
}

Eigen::Isometry3d Simulator::T_map_odom_at(double time_s) const {
  if (corrections_.empty()) return T_map_odom();  // none published yet (or localization disabled): exact
  const std::uint64_t k = correction_index(config_.localization, time_s);
  return corrections_[std::min<std::size_t>(k, corrections_.size() - 1)].T_map_odom;
}

void Simulator::publish_corrections() {
  const LocalizationConfig& loc = config_.localization;
  // Correction k at k / rate_hz, published at the first step at or after it (at its time for a rate whose period is
  // a whole number of timesteps): the estimate of the robot now, off the truth by the correction's error.
  while (corrections_.size() / loc.rate_hz <= time_s() + 1e-9) {
    const std::uint64_t k = corrections_.size();
    const PoseError2 e = localization_error(loc, loc.seed, k);
    Eigen::Isometry3d T_map_base = T_world_base();
    T_map_base.linear() = Eigen::AngleAxisd(e.yaw_rad, Eigen::Vector3d::UnitZ()) * T_map_base.linear();
    T_map_base.translation() += Eigen::Vector3d(e.x_m, e.y_m, 0.0);
    corrections_.push_back({static_cast<double>(k) / loc.rate_hz, T_map_base * T_odom_base().inverse(), e});
  }
}

void Simulator::set_path(const Path& path) {
  follower_.set_path(path);
  if (!kinematic_) return;
  if (path.reverse)
    throw std::invalid_argument(
        "robot.reverse needs robot.drive physics: the kinematic drive places the base "
        "facing along the path");
  const Eigen::Isometry3d T = robot_.T_world_base();
  const Eigen::Vector3d x_axis = T.linear().col(0);
  kinematic_->set_path(path, {T.translation().x(), T.translation().y(), std::atan2(x_axis.y(), x_axis.x())}, time_s());
}

void Simulator::set_mocap_tracks(std::vector<MocapTrack> tracks) {
  mocap_ = MocapScript(world_, std::move(tracks));
  mocap_.apply(world_.model(), world_.data(), world_.time_s());
  world_.forward();
}

void Simulator::set_controller(TwistController controller, double period_s) {
  if (!(period_s > 0) || !std::isfinite(period_s))
    throw std::invalid_argument("controller period " + std::to_string(period_s) + " s must be a positive number");
  if (follower_.has_path()) throw std::invalid_argument("a robot with a path takes no controller");
  controller_ = std::move(controller);
  steps_per_controller_ = std::max(1L, std::lround(period_s / world_.timestep_s()));
  step_count_ = 0;  // the first call at the next step
}

void Simulator::step() {
  advance();
  if (config_.localization.enabled) publish_corrections();
}

void Simulator::advance() {
  if (controller_ && step_count_ % steps_per_controller_ == 0) {
    commanded_ = controller_(time_s());
    if (!kinematic_) robot_.command_twist(commanded_.v_mps, commanded_.omega_radps);
  }
  if (kinematic_) {
    kinematic_step();
    return;
  }
  if (step_count_ % steps_per_control_ == 0 && follower_.has_path()) {
    const Eigen::Isometry3d T = robot_.T_world_base();
    const Eigen::Vector3d x_axis = T.linear().col(0);
    const Twist2D twist = follower_.update(T.translation().head<2>(), std::atan2(x_axis.y(), x_axis.x()));
    robot_.command_twist(twist.v_mps, twist.omega_radps);
  }
  const double dt = world_.timestep_s();
  robot_.apply_controls(dt);
  mjModel* m = world_.mutable_model();
  mjData* d = world_.data();
  mj_step2(m, d);
  mocap_.apply(m, d, d->time);
  mj_step1(m, d);
  const Eigen::Vector2d rates = robot_.wheel_rates_radps();
  odometry_.update(rates.x(), rates.y(), dt);
  ++step_count_;
}

void Simulator::kinematic_step() {
  const double dt = world_.timestep_s();
  mjModel* m = world_.mutable_model();
  mjData* d = world_.data();
  mj_step2(m, d);     // the rest of the world moves on; the robot's own integration is overwritten below
  if (controller_) {  // the commanded twist integrated along an arc's chord (midpoint heading)
    const double yaw_mid = hold_.yaw_rad + 0.5 * commanded_.omega_radps * dt;
    hold_.x_m += commanded_.v_mps * std::cos(yaw_mid) * dt;
    hold_.y_m += commanded_.v_mps * std::sin(yaw_mid) * dt;
    hold_.yaw_rad = std::remainder(hold_.yaw_rad + commanded_.omega_radps * dt, 2 * M_PI);
  }
  const KinematicDrive::State state = kinematic_->has_path()
                                          ? kinematic_->at(d->time)
                                          : KinematicDrive::State{hold_, controller_ ? commanded_ : Twist2D{}};
  robot_.place(state.pose, state.twist, dt);
  mocap_.apply(m, d, d->time);
  mj_step1(m, d);
  const Eigen::Vector2d rates = robot_.wheel_rates_radps();
  odometry_.update(rates.x(), rates.y(), dt);
  ++step_count_;
}

void Simulator::run_until(double t_s) {
  if (!std::isfinite(t_s)) throw std::invalid_argument("run_until: time_s is not finite");
  while (world_.time_s() < t_s - 1e-12) step();
}

}  // namespace stvl::sim

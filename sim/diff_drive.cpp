#include "sim/diff_drive.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace stvl::sim {
namespace {

Eigen::Quaterniond to_eigen_quat(const mjtNum* q) { return Eigen::Quaterniond(q[0], q[1], q[2], q[3]); }

void to_mj_quat(const Eigen::Quaterniond& q, mjtNum* out) {
  out[0] = q.w();
  out[1] = q.x();
  out[2] = q.y();
  out[3] = q.z();
}

double step_toward(double current, double target, double max_delta) {
  return current + std::clamp(target - current, -max_delta, max_delta);
}

int hinge_dof(const World& world, const std::string& joint) {
  const int id = world.joint_id(joint);
  if (world.model()->jnt_type[id] != mjJNT_HINGE) {
    throw std::invalid_argument("wheel joint '" + joint + "' is not a hinge");
  }
  return id;
}

}  // namespace

DiffDriveRobot::DiffDriveRobot(World& world, DiffDriveConfig config) : world_(&world), config_(std::move(config)) {
  const mjModel* m = world.model();
  base_body_ = world.body_id(config_.base_body);
  const int left_joint = hinge_dof(world, config_.left_joint);
  const int right_joint = hinge_dof(world, config_.right_joint);
  left_dof_ = m->jnt_dofadr[left_joint];
  right_dof_ = m->jnt_dofadr[right_joint];
  left_qpos_ = m->jnt_qposadr[left_joint];
  right_qpos_ = m->jnt_qposadr[right_joint];
  left_act_ = world.actuator_id(config_.left_actuator);
  right_act_ = world.actuator_id(config_.right_actuator);
  link_site_ = world.site_id(config_.camera_link_site);
  optical_site_ = world.site_id(config_.optical_site);
  if (m->site_bodyid[link_site_] != base_body_ || m->site_bodyid[optical_site_] != base_body_) {
    throw std::invalid_argument("camera sites must be attached to body '" + config_.base_body + "'");
  }
  if (!config_.camera.empty()) {
    camera_ = mj_name2id(m, mjOBJ_CAMERA, config_.camera.c_str());
  }
  const int free_joint = m->body_jntadr[base_body_];
  if (free_joint < 0 || m->jnt_type[free_joint] != mjJNT_FREE) {
    throw std::invalid_argument("body '" + config_.base_body + "' has no freejoint");
  }
  free_qpos_ = m->jnt_qposadr[free_joint];
  free_dof_ = m->jnt_dofadr[free_joint];

  if (config_.wheel_radius_m > 0 || config_.track_width_m > 0) {
    wheel_radius_m_ = config_.wheel_radius_m;
    track_width_m_ = config_.track_width_m;
  } else {
    const int left_body = m->jnt_bodyid[left_joint];
    const int right_body = m->jnt_bodyid[right_joint];
    if (m->body_geomnum[left_body] < 1 || m->geom_type[m->body_geomadr[left_body]] != mjGEOM_CYLINDER) {
      throw std::invalid_argument("wheel body of '" + config_.left_joint + "' needs a cylinder geom");
    }
    wheel_radius_m_ = m->geom_size[3 * m->body_geomadr[left_body]];
    track_width_m_ = std::abs(m->body_pos[3 * left_body + 1] - m->body_pos[3 * right_body + 1]);
  }
  if (!(wheel_radius_m_ > 0) || !(track_width_m_ > 0)) {
    throw std::invalid_argument("degenerate wheel geometry in world '" + world.source() + "'");
  }
  const Eigen::Vector3d p(m->site_pos[3 * link_site_], m->site_pos[3 * link_site_ + 1],
                          m->site_pos[3 * link_site_ + 2]);
  const Eigen::Vector3d x_axis = to_eigen_quat(m->site_quat + 4 * link_site_) * Eigen::Vector3d::UnitX();
  mount_ = CameraMount{p.z(), std::atan2(-x_axis.z(), x_axis.x()), p.x()};
}

void DiffDriveRobot::command_twist(double v_mps, double omega_radps) {
  if (!std::isfinite(v_mps) || !std::isfinite(omega_radps)) {
    throw std::invalid_argument("non-finite twist command v=" + std::to_string(v_mps) +
                                " omega=" + std::to_string(omega_radps));
  }
  v_target_ = std::clamp(v_mps, -config_.max_linear_speed_mps, config_.max_linear_speed_mps);
  omega_target_ = std::clamp(omega_radps, -config_.max_angular_speed_radps, config_.max_angular_speed_radps);
}

void DiffDriveRobot::apply_controls(double dt_s) {
  v_mps_ = step_toward(v_mps_, v_target_, config_.max_linear_accel_mps2 * dt_s);
  omega_radps_ = step_toward(omega_radps_, omega_target_, config_.max_angular_accel_radps2 * dt_s);
  const double half_track = 0.5 * track_width_m_;
  mjData* d = world_->data();
  d->ctrl[left_act_] = (v_mps_ - omega_radps_ * half_track) / wheel_radius_m_;
  d->ctrl[right_act_] = (v_mps_ + omega_radps_ * half_track) / wheel_radius_m_;
}

Eigen::Vector2d DiffDriveRobot::wheel_rates_radps() const {
  const mjData* d = world_->data();
  return {d->qvel[left_dof_], d->qvel[right_dof_]};
}

Eigen::Isometry3d DiffDriveRobot::T_world_base() const {
  const mjData* d = world_->data();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = to_eigen_quat(d->xquat + 4 * base_body_).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(d->xpos[3 * base_body_], d->xpos[3 * base_body_ + 1], d->xpos[3 * base_body_ + 2]);
  return T;
}

void DiffDriveRobot::set_pose(double x_m, double y_m, double yaw_rad) {
  if (!std::isfinite(x_m) || !std::isfinite(y_m) || !std::isfinite(yaw_rad)) {
    throw std::invalid_argument("non-finite robot pose");
  }
  mjData* d = world_->data();
  const mjModel* m = world_->model();
  d->qpos[free_qpos_ + 0] = x_m;
  d->qpos[free_qpos_ + 1] = y_m;
  d->qpos[free_qpos_ + 2] = m->body_pos[3 * base_body_ + 2];
  to_mj_quat(Eigen::Quaterniond(Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ())), d->qpos + free_qpos_ + 3);
  for (int i = 0; i < m->nv; ++i) d->qvel[i] = 0;
  v_target_ = omega_target_ = v_mps_ = omega_radps_ = 0;
  world_->forward();
}

void DiffDriveRobot::place(const Pose2D& pose, const Twist2D& twist, double dt_s) {
  mjData* d = world_->data();
  const mjModel* m = world_->model();
  const double c = std::cos(pose.yaw_rad), s = std::sin(pose.yaw_rad);
  d->qpos[free_qpos_ + 0] = pose.x_m;
  d->qpos[free_qpos_ + 1] = pose.y_m;
  d->qpos[free_qpos_ + 2] = m->body_pos[3 * base_body_ + 2];
  to_mj_quat(Eigen::Quaterniond(Eigen::AngleAxisd(pose.yaw_rad, Eigen::Vector3d::UnitZ())), d->qpos + free_qpos_ + 3);
  // A freejoint's velocity: linear in the world frame, angular in the body's (yaw only: the same).
  const double qvel[6] = {twist.v_mps * c, twist.v_mps * s, 0, 0, 0, twist.omega_radps};
  std::copy(qvel, qvel + 6, d->qvel + free_dof_);
  v_target_ = v_mps_ = twist.v_mps;
  omega_target_ = omega_radps_ = twist.omega_radps;
  const double half_track = 0.5 * track_width_m_;
  const double left = (twist.v_mps - twist.omega_radps * half_track) / wheel_radius_m_;
  const double right = (twist.v_mps + twist.omega_radps * half_track) / wheel_radius_m_;
  d->qvel[left_dof_] = left, d->qvel[right_dof_] = right;
  d->qpos[left_qpos_] += left * dt_s, d->qpos[right_qpos_] += right * dt_s;
}

double DiffDriveRobot::tilt_rad() const {
  const Eigen::Vector3d z = T_world_base().linear().col(2);
  return std::acos(std::clamp(z.z(), -1.0, 1.0));
}

void DiffDriveRobot::set_camera_mount(const CameraMount& mount) {
  if (!(mount.height_m >= 0.3 && mount.height_m <= 1.2)) {
    throw std::invalid_argument("camera mount height_m " + std::to_string(mount.height_m) + " outside [0.3, 1.2]");
  }
  if (!(std::abs(mount.pitch_rad) <= 1.0)) {
    throw std::invalid_argument("camera mount pitch_rad " + std::to_string(mount.pitch_rad) + " outside [-1, 1]");
  }
  if (!(mount.forward_offset_m >= -0.3 && mount.forward_offset_m <= 0.6)) {
    throw std::invalid_argument("camera mount forward_offset_m " + std::to_string(mount.forward_offset_m) +
                                " outside [-0.3, 0.6]");
  }
  mount_ = mount;
  mjModel* m = world_->mutable_model();
  const Eigen::Isometry3d T_link = T_base_camera_link();
  const Eigen::Isometry3d T_optical = T_link * T_camera_link_optical();
  for (int i = 0; i < 3; ++i) {
    m->site_pos[3 * link_site_ + i] = T_link.translation()[i];
    m->site_pos[3 * optical_site_ + i] = T_link.translation()[i];
  }
  to_mj_quat(Eigen::Quaterniond(T_link.linear()), m->site_quat + 4 * link_site_);
  to_mj_quat(Eigen::Quaterniond(T_optical.linear()), m->site_quat + 4 * optical_site_);
  if (camera_ >= 0 && m->cam_bodyid[camera_] == base_body_) {
    // MuJoCo cameras look along -z with y up: the optical frame turned half a turn about x.
    const Eigen::Matrix3d R_cam = T_optical.linear() * Eigen::Vector3d(1, -1, -1).asDiagonal();
    for (int i = 0; i < 3; ++i) m->cam_pos[3 * camera_ + i] = T_link.translation()[i];
    to_mj_quat(Eigen::Quaterniond(R_cam), m->cam_quat + 4 * camera_);
  }
  world_->forward();
}

Eigen::Isometry3d T_base_camera_link(const CameraMount& mount) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(mount.forward_offset_m, mount.lateral_offset_m, mount.height_m);
  T.linear() = Eigen::AngleAxisd(mount.pitch_rad, Eigen::Vector3d::UnitY()).toRotationMatrix();
  // Kept apart so that a mount without roll and yaw gives the same bits as before they existed.
  if (mount.roll_rad != 0.0 || mount.yaw_rad != 0.0)
    T.linear() = (Eigen::AngleAxisd(mount.yaw_rad, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(mount.pitch_rad, Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(mount.roll_rad, Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
  return T;
}

Eigen::Isometry3d DiffDriveRobot::T_base_camera_link() const { return sim::T_base_camera_link(mount_); }

std::string DiffDriveRobot::geom_containing(const Eigen::Vector3d& p_base, int own_body) const {
  const mjModel* m = world_->model();
  const auto own = [&](int body) {
    for (int b = own_body; b > 0 && b != base_body_; b = m->body_parentid[b])
      if (b == body) return true;
    return false;
  };
  for (int g = 0; g < m->ngeom; ++g) {
    if (own(m->geom_bodyid[g])) continue;
    // The geom's pose in base_link at rest: up its body chain to base_link.
    int body = m->geom_bodyid[g];
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(m->geom_pos[3 * g], m->geom_pos[3 * g + 1], m->geom_pos[3 * g + 2]);
    T.linear() = to_eigen_quat(m->geom_quat + 4 * g).normalized().toRotationMatrix();
    while (body != base_body_ && body > 0) {
      Eigen::Isometry3d T_parent_body = Eigen::Isometry3d::Identity();
      T_parent_body.translation() =
          Eigen::Vector3d(m->body_pos[3 * body], m->body_pos[3 * body + 1], m->body_pos[3 * body + 2]);
      T_parent_body.linear() = to_eigen_quat(m->body_quat + 4 * body).normalized().toRotationMatrix();
      T = T_parent_body * T;
      body = m->body_parentid[body];
    }
    if (body != base_body_) continue;
    const Eigen::Vector3d p = T.inverse() * p_base;
    const mjtNum* size = m->geom_size + 3 * g;
    bool inside = false;
    switch (m->geom_type[g]) {
      case mjGEOM_BOX:
        inside = std::abs(p.x()) <= size[0] && std::abs(p.y()) <= size[1] && std::abs(p.z()) <= size[2];
        break;
      case mjGEOM_SPHERE: inside = p.norm() <= size[0]; break;
      case mjGEOM_CYLINDER: inside = p.head<2>().norm() <= size[0] && std::abs(p.z()) <= size[1]; break;
      default: inside = p.norm() <= m->geom_rbound[g];
    }
    if (inside) {
      const char* name = mj_id2name(m, mjOBJ_GEOM, g);
      return name ? name : "geom " + std::to_string(g);
    }
  }
  return {};
}

Eigen::Isometry3d DiffDriveRobot::T_camera_link_optical() {
  Eigen::Matrix3d R;  // columns: optical x, y, z expressed in camera_link
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  return T;
}

Eigen::Isometry3d DiffDriveRobot::T_world_camera() const {
  const mjData* d = world_->data();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = d->site_xmat[9 * optical_site_ + 3 * r + c];
  T.linear() = R;
  T.translation() = Eigen::Vector3d(d->site_xpos[3 * optical_site_], d->site_xpos[3 * optical_site_ + 1],
                                    d->site_xpos[3 * optical_site_ + 2]);
  return T;
}

}  // namespace stvl::sim

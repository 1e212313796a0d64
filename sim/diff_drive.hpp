#pragma once
// The differential-drive robot of worlds/robot.xml inside a World: wheel velocity commands with
// acceleration limits, ground-truth pose, run-time camera mount.
#include <string>

#include <Eigen/Geometry>

#include "sim/path_follower.hpp"
#include "sim/world.hpp"

namespace stvl::sim {

struct DiffDriveConfig {
  std::string base_body = "base_link";
  std::string left_joint = "left_wheel_joint";
  std::string right_joint = "right_wheel_joint";
  std::string left_actuator = "left_wheel";
  std::string right_actuator = "right_wheel";
  std::string camera_link_site = "camera_link";
  std::string optical_site = "camera_depth_optical_frame";
  std::string camera = "camera_depth";  // MuJoCo camera (x right, y up, looks along -z); optional
  // 0: read from the model as robot.xml lays it out (the first geom of each wheel body a cylinder, the wheel
  // bodies' y on base_link); a URDF robot gives both (sim/urdf_robot.hpp).
  double wheel_radius_m = 0.0;
  double track_width_m = 0.0;
  double max_linear_speed_mps = 1.2;
  double max_angular_speed_radps = 2.0;
  double max_linear_accel_mps2 = 1.0;
  double max_angular_accel_radps2 = 3.0;
};

// camera_link pose on base_link (x forward, y left, z up; its origin is on the floor): `forward_offset_m`
// along x, `lateral_offset_m` along y, `height_m` above the floor; turned as URDF's rpy, R = Rz(yaw) Ry(pitch)
// Rx(roll): positive pitch looks down, positive yaw looks left.
struct CameraMount {
  double height_m = 0.5;
  double pitch_rad = 0.0;
  double forward_offset_m = 0.1;
  double lateral_offset_m = 0.0;
  double roll_rad = 0.0;
  double yaw_rad = 0.0;
};

// camera_link on base_link for `mount`.
Eigen::Isometry3d T_base_camera_link(const CameraMount& mount);

class DiffDriveRobot {
 public:
  // Keeps a pointer to `world`, which must outlive the robot and not move.
  // Wheel radius and track width are read from the model.
  explicit DiffDriveRobot(World& world, DiffDriveConfig config = {});

  double wheel_radius_m() const { return wheel_radius_m_; }
  double track_width_m() const { return track_width_m_; }
  const DiffDriveConfig& config() const { return config_; }

  // Target body twist, clamped to the speed limits; reached under the acceleration limits.
  void command_twist(double v_mps, double omega_radps);
  // Rate-limits the current command toward the target over dt_s and writes the wheel controls.
  void apply_controls(double dt_s);
  double commanded_v_mps() const { return v_mps_; }
  double commanded_omega_radps() const { return omega_radps_; }

  // Measured wheel joint rates (rad/s), left then right; positive drives forward.
  Eigen::Vector2d wheel_rates_radps() const;
  Eigen::Isometry3d T_world_base() const;
  // Places the base on the floor at (x, y, yaw), at rest; call before stepping.
  void set_pose(double x_m, double y_m, double yaw_rad);
  // Angle between base z and world z.
  double tilt_rad() const;
  // Kinematic drive: puts the base at `pose` on the floor (its rest height, level) moving with `twist`, and turns
  // the wheels at the matching rates over dt_s (for looks and odometry). Call after the physics step.
  void place(const Pose2D& pose, const Twist2D& twist, double dt_s);

  // Moves the camera sites (and camera) on the model; throws std::invalid_argument out of range
  // (height 0.3..1.2 m, |pitch| <= 1.0 rad, forward offset -0.3..0.6 m).
  void set_camera_mount(const CameraMount& mount);
  const CameraMount& camera_mount() const { return mount_; }
  Eigen::Isometry3d T_base_camera_link() const;
  // camera_link (x forward, y left, z up) -> optical frame (z forward, x right, y down); constant.
  static Eigen::Isometry3d T_camera_link_optical();
  // World pose of the optical frame site.
  Eigen::Isometry3d T_world_camera() const;
  // Name of the robot geom (base_link's and its wheels', at rest) that holds p_base, a point in base_link;
  // empty when none does. Boxes, spheres and cylinders exactly, other shapes by their bounding spheres. The geoms
  // of `own_body` and of its ancestors below base_link (a camera's housing; -1: none) do not count.
  std::string geom_containing(const Eigen::Vector3d& p_base, int own_body = -1) const;

  int base_body_id() const { return base_body_; }

 private:
  World* world_;
  DiffDriveConfig config_;
  CameraMount mount_;
  int base_body_, left_dof_, right_dof_, left_qpos_, right_qpos_, left_act_, right_act_, link_site_, optical_site_;
  int camera_ = -1;
  int free_qpos_, free_dof_;
  double wheel_radius_m_ = 0, track_width_m_ = 0;
  double v_target_ = 0, omega_target_ = 0, v_mps_ = 0, omega_radps_ = 0;
};

}  // namespace stvl::sim

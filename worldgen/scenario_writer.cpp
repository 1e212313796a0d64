#include "worldgen/scenario_writer.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "worldgen/mjcf_writer.hpp"
#include "worldgen/planner.hpp"

namespace stvl::worldgen {
namespace {

constexpr double kCornerRad = 0.5;      // sim::PathFollowerConfig::corner_angle_rad
constexpr double kTurnRateRadps = 0.8;  // below the follower's 1.2 rad/s: it accelerates and brakes
constexpr double kStopAndGoS = 2.0;

double turn(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return std::abs(std::remainder(std::atan2(b.y(), b.x()) - std::atan2(a.y(), a.x()), 2 * M_PI));
}

std::string point(const Eigen::Vector2d& p) { return "[" + fixed(p.x(), 3) + ", " + fixed(p.y(), 3) + "]"; }

int sharp_corners(const std::vector<Eigen::Vector2d>& w) {
  int n = 0;
  for (std::size_t i = 1; i + 1 < w.size(); ++i) n += turn(w[i] - w[i - 1], w[i + 1] - w[i]) > kCornerRad;
  return n;
}

// The sensing, filtering and mapping of scenarios/office_corridor.yaml (the default scenario).
constexpr const char* kSensingAndMap = R"(camera:
  preset: d435_848x480
  rate_hz: 15
  noise: {enabled: true}
filter:
  type: voxel
  device: auto
  passthrough: {enabled: true, min_z_m: 0.1, max_z_m: 2.0}
  voxel: {voxel_size_m: 0.05, min_points_per_voxel: 3}
map:
  voxel_size: 0.05
  voxel_decay: 15
  decay_model: linear
  mark_threshold: 0
  clearing_mode: frustum
  observation:
    obstacle_range: 3.0
    min_obstacle_height: 0.1
    max_obstacle_height: 2.0
    min_z: 0.1
    max_z: 4.0
    decay_acceleration: 5.0
evaluation:
  recall_window_s: 2.0
  evaluate_every_s: 1.0
  tolerance_voxels: 1
)";

}  // namespace

double drive_duration_s(const std::vector<Eigen::Vector2d>& w, double speed_mps, double start_yaw_rad) {
  double time_s = path_length_m(w) / speed_mps;
  if (w.size() >= 2) {
    const Eigen::Vector2d heading(std::cos(start_yaw_rad), std::sin(start_yaw_rad));
    time_s += turn(heading, w[1] - w[0]) / kTurnRateRadps + kStopAndGoS;
  }
  for (std::size_t i = 1; i + 1 < w.size(); ++i) {
    const double angle = turn(w[i] - w[i - 1], w[i + 1] - w[i]);
    if (angle > kCornerRad) time_s += angle / kTurnRateRadps + kStopAndGoS;
  }
  return std::ceil(1.3 * time_s + 10.0);
}

std::string write_scenario_yaml(const ScenarioSpec& s) {
  const double yaw_rad = s.start.z() * M_PI / 180.0;
  const double duration_s = drive_duration_s(s.waypoints_W, s.speed_mps, yaw_rad);
  const double length_m = path_length_m(s.waypoints_W);
  if (duration_s > 3600)
    throw std::invalid_argument("the planned path is " + fixed(length_m, 1) +
                                " m long, more than a 3600 s scenario drives at " + fixed(s.speed_mps, 2) +
                                " m/s; give a nearer --goal");
  std::ostringstream y;
  std::istringstream lines(s.description);
  for (std::string line; std::getline(lines, line);) y << "#" << (line.empty() ? "" : " ") << line << "\n";
  y << "# Keys are documented in scenarios/README.md.\n"
    << "name: " << s.name << "\n"
    << "world: " << s.world_file << "\n"
    << "seed: " << s.seed << "\n"
    << "# The path's " << fixed(length_m, 1) << " m at " << fixed(s.speed_mps, 1)
    << " m/s, a stop and a turn in place at each of its " << sharp_corners(s.waypoints_W)
    << " sharp corners and at the start,\n"
    << "# then 30 % and 10 s spare (the run stops at the path's end).\n"
    << "duration_s: " << fixed(duration_s, 0) << "\n"
    << "robot:\n"
    << "  start: [" << fixed(s.start.x(), 3) << ", " << fixed(s.start.y(), 3) << ", " << fixed(s.start.z(), 1)
    << "]  # x_m, y_m, yaw_deg: the path's first point, facing its first leg\n"
    << "  # A* on the world's floor plan (8-connected, a clearance term in the cost), every cell of it at least the\n"
    << "  # robot's footprint radius (worlds/robot.xml) plus 0.05 m from any wall or obstacle, pruned to the legs that "
       "keep\n"
    << "  # the clearance the cell path had.\n"
    << "  waypoints: [";
  for (std::size_t i = 0; i < s.waypoints_W.size(); ++i) y << (i ? ", " : "") << point(s.waypoints_W[i]);
  y << "]\n"
    << "  speed_mps: " << fixed(s.speed_mps, 2) << "\n"
    << "  camera_mount: {height_m: 0.5, pitch_deg: 5, forward_offset_m: 0.15}\n";
  if (!s.moving_bodies.empty()) {
    y << "moving_bodies:\n";
    for (const MovingBodySpec& m : s.moving_bodies) {
      y << "  - body: " << m.body << (m.comment.empty() ? "" : "  # " + m.comment) << "\n    keyframes:\n";
      for (const Keyframe& k : m.keyframes)
        y << "      - {t: " << fixed(k.t_s, 2) << ", position: [" << fixed(k.position_W.x(), 3) << ", "
          << fixed(k.position_W.y(), 3) << ", " << fixed(k.position_W.z(), 3) << "], yaw_deg: " << fixed(k.yaw_deg, 1)
          << "}\n";
      if (m.repeat_s) y << "    repeat_s: " << fixed(*m.repeat_s, 2) << "\n";
    }
  }
  y << "# Sensing, filter and map as in scenarios/office_corridor.yaml.\n" << kSensingAndMap;
  y << "# Besides robot_upright, path_completed (the path's end reached within duration_s) and the default mean "
       "costmap\n"
    << "# precision >= 0.7 (evaluation/checks.hpp):\n"
    << "checks:\n"
    << "  # Generic bounds, not measured on this world: every generated world is new, so these are the bounds any of "
       "them\n"
    << "  # must meet. README.md (\"Your building, your robot\") gives what generated worlds measured when the "
       "generator\n"
    << "  # was written. 0.9 fails a map that gets a tenth of what the camera saw wrong.\n"
    << "  f1_3d_min: 0.9\n"
    << "  # Flying pixels at the edges the robot passes close by (door jambs) leave a few isolated lethal cells on its "
       "way\n"
    << "  # (STVL has no edge filter). 10 cells still fails a floor marked lethal (thousands, evaluation/checks.hpp).\n"
    << "  path_free_lethal_max: 10\n";
  return y.str();
}

}  // namespace stvl::worldgen

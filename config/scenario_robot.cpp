// A scenario's robot from a URDF (robot.urdf, package_path, wheels, drive), cameras at its links
// (robot.cameras[i].frame), and where the footprint comes from.
#include <cmath>
#include <filesystem>
#include <memory>

#include "config/scenario_detail.hpp"
#include "sim/urdf_robot.hpp"

namespace stvl::config::scenario_detail {
namespace {

std::string resolved(const std::string& path, const std::string& base_dir) {
  return std::filesystem::path(path).is_absolute()
             ? path
             : (std::filesystem::path(base_dir) / path).lexically_normal().string();
}

}  // namespace

void read_urdf_robot(YamlMap& robot, Scenario& s, const std::string& base_dir) {
  if (!robot.has("urdf")) {
    for (const char* key : {"package_path", "wheels", "drive"})
      if (robot.has(key)) robot.fail(robot.raw(key), key, "needs robot.urdf (the robot's URDF file)");
    return;
  }
  sim::UrdfRobotConfig c;
  robot.require("urdf", c.urdf);
  require_range(robot, "urdf", "an empty path", !c.urdf.empty(), "must not be empty");
  c.urdf = resolved(c.urdf, base_dir);
  robot.get("package_path", c.package_path);
  for (auto& entry : c.package_path) {
    require_range(robot, "package_path", "an empty folder", !entry.empty(), "entries must not be empty");
    entry = resolved(entry, base_dir);
    if (!std::filesystem::is_directory(entry))
      robot.fail(robot.raw("package_path"), "package_path", "no folder " + entry);
  }
  if (robot.has("wheels")) {
    auto wheels = robot.map("wheels");
    auto& w = c.wheels;
    wheels.get("left", w.left_joint);
    wheels.get("right", w.right_joint);
    wheels.get("radius_m", w.radius_m);
    wheels.get("separation_m", w.separation_m);
    wheels.finish();
    if (w.left_joint.empty() != w.right_joint.empty())
      wheels.fail(wheels.raw(w.left_joint.empty() ? "right" : "left"), w.left_joint.empty() ? "right" : "left",
                  "name both wheel joints, left and right (or neither: then they are found)");
    for (const auto& [key, value] :
         {std::pair<const char*, double>{"radius_m", w.radius_m}, {"separation_m", w.separation_m}})
      require_range(wheels, key, value, std::isfinite(value) && value >= 0,
                    "must be finite and >= 0 m (0: from the URDF)");
  }
  std::string drive = sim::to_string(c.drive);
  robot.get("drive", drive);
  validate_keys({{"drive", &robot, "drive"}}, [&] { c.drive = sim::parse_drive_mode(drive); });
  c.probe_speed_mps = s.pipeline.path.cruise_speed_mps;
  try {
    s.pipeline.urdf_robot = std::make_shared<const sim::UrdfRobot>(sim::build_urdf_robot(c));
  } catch (const std::invalid_argument& e) {
    robot.fail(robot.raw("urdf"), "urdf", e.what());
  }
  s.pipeline.sim.robot = s.pipeline.urdf_robot->diff_drive_config();
  s.pipeline.sim.drive = s.pipeline.urdf_robot->drive;
}

void read_camera_frame(YamlMap& camera, const Scenario& s, pipeline::CameraConfig& c) {
  if (camera.has("mount")) camera.fail(camera.raw("mount"), "mount", "give frame or mount, not both");
  camera.require("frame", c.frame);
  if (!s.pipeline.urdf_robot)
    camera.fail(camera.raw("frame"), "frame", "needs robot.urdf (a link of the robot's URDF), or give a mount");
  try {
    c.mount = sim::camera_mount_at(s.pipeline.urdf_robot->urdf, c.frame);
  } catch (const std::invalid_argument& e) {
    camera.fail(camera.raw("frame"), "frame", e.what());
  }
}

void complete_footprint(Scenario& s) {
  const auto& robot = s.pipeline.urdf_robot;
  if (!s.pipeline.map.footprint_B.empty() || !robot) return;
  s.pipeline.map.footprint_B = robot->footprint_B;
  s.footprint_source = "URDF collision shapes (" + robot->config.urdf + ")";
}

}  // namespace stvl::config::scenario_detail

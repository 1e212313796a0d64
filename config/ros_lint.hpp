#pragma once
// Findings on an STVL layer as a ROS parameter file writes it: keys that version of STVL does not read, and
// values it reads in a way users rarely mean (see scenarios/README.md, "ROS parameter files and
// `stvl-bench lint`").
#include <string>
#include <vector>

namespace stvl::config {

struct LintFinding {
  std::string file;
  int line = 0;     // 1-based
  std::string key;  // dotted, as ROS names the parameter ("stvl_layer.pointcloud.voxel_filter")
  std::string what_stvl_does;
  std::string write_instead;
};

// The camera a source is bound to (known at run time only): its real field of view (full angles, radians), its
// name and, when height_m > 0, its mount (optical centre above a flat floor, pitch positive down, roll; the bench's
// R = Rz(yaw) Ry(pitch) Rx(roll)) and depth range.
struct BoundCamera {
  std::string source;
  double hfov_rad = 0.0, vfov_rad = 0.0;
  std::string camera;  // "" when only the FOV is known: sources are then grouped by topic or sensor_frame
  double height_m = 0.0, pitch_rad = 0.0, roll_rad = 0.0;
  double max_range_m = 0.0;  // 0 unknown
};

// The findings on the layer load_ros_stvl_layer() would read (same `layer` and `costmap` rules), sorted by
// line. Sources share a camera when `cameras` binds them to the same one, otherwise when they read the same topic
// (or, without a topic, the same sensor_frame); lint reasons across the enabled sources of one camera with STVL's
// depth-camera frustum (ros2 403d9ed, noetic-devel 5e06daf). FOV findings only for clearing sources named in
// `cameras`; height findings only for cameras with a mount. Throws std::invalid_argument where
// load_ros_stvl_layer() does, except for a negative voxel_decay (a finding here).
std::vector<LintFinding> lint_ros_stvl_layer(const std::string& path, const std::string& layer,
                                             const std::string& costmap = "",
                                             const std::vector<BoundCamera>& cameras = {});

// "file:line: key: what STVL does; write instead: ..."
std::string format_finding(const LintFinding& finding);

}  // namespace stvl::config

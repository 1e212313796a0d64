#pragma once
// Findings on an STVL layer as a ROS parameter file writes it: keys that version of STVL does not read, and
// values it reads in a way users rarely mean (see scenarios/README.md, "ROS parameter files and
// `stvl-bench lint`").
#include <string>
#include <vector>

namespace stvl::config {

struct LintFinding {
  std::string file;
  int line = 0;          // 1-based
  std::string key;       // dotted, as ROS names the parameter ("stvl_layer.pointcloud.voxel_filter")
  std::string what_stvl_does;
  std::string write_instead;
};

// The real field of view of the camera a source is bound to (known at run time only), full angles in radians.
struct BoundCamera {
  std::string source;
  double hfov_rad = 0.0, vfov_rad = 0.0;
};

// The findings on the layer load_ros_stvl_layer() would read (same `layer` and `costmap` rules), sorted by
// line. FOV findings only for sources named in `cameras`. Throws std::invalid_argument where
// load_ros_stvl_layer() does, except for a negative voxel_decay (a finding here).
std::vector<LintFinding> lint_ros_stvl_layer(const std::string& path, const std::string& layer,
                                             const std::string& costmap = "",
                                             const std::vector<BoundCamera>& cameras = {});

// "file:line: key: what STVL does; write instead: ..."
std::string format_finding(const LintFinding& finding);

}  // namespace stvl::config

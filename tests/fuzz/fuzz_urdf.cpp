// URDF reader (robot_description/urdf_model.hpp): any text either reads into a tree whose every link has a finite
// pose, or throws std::invalid_argument naming the file (what `stvl-bench run` turns into exit 2). The MJCF written
// from a tree that reads must be well-formed. Any other exception, crash or sanitizer report is a finding.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include <tinyxml2.h>

#include "robot_description/urdf_mjcf.hpp"
#include "robot_description/urdf_model.hpp"
#include "sim/urdf_robot.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  stvl::robot_description::UrdfModel urdf;
  try {
    urdf = stvl::robot_description::parse_urdf(text, "fuzz.urdf", {});
  } catch (const std::invalid_argument& e) {
    if (std::string(e.what()).rfind("fuzz.urdf", 0) != 0) {
      std::fprintf(stderr, "error message does not start with the file: %s\n", e.what());
      std::abort();
    }
    return 0;
  }
  if (urdf.root.empty() || !urdf.find_link(urdf.root) || urdf.parent_joint(urdf.root)) std::abort();
  for (const auto& link : urdf.links) {
    if (!urdf.T_root_link(link.name).matrix().allFinite()) std::abort();
    const stvl::sim::CameraMount m = stvl::sim::camera_mount_at(urdf, link.name);
    if (!std::isfinite(m.height_m + m.pitch_rad + m.roll_rad + m.yaw_rad + m.forward_offset_m + m.lateral_offset_m))
      std::abort();
  }
  const stvl::robot_description::MjcfRobot mjcf = stvl::robot_description::urdf_to_mjcf(urdf, {});
  tinyxml2::XMLDocument doc;
  if (doc.Parse(mjcf.xml.c_str()) != tinyxml2::XML_SUCCESS) {
    std::fprintf(stderr, "the MJCF written does not parse: %s\n", doc.ErrorStr());
    std::abort();
  }
  return 0;
}

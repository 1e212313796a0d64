#include "worldgen/mjcf_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "sim/world.hpp"

namespace stvl::worldgen {
namespace {

// XML comments may not hold "--".
std::string comment_text(std::string text) {
  for (std::size_t at = text.find("--"); at != std::string::npos; at = text.find("--", at)) text.replace(at, 2, "- ");
  return text;
}

std::string join(const std::vector<double>& values, int decimals) {
  std::string out;
  for (double v : values) out += (out.empty() ? "" : " ") + fixed(v, decimals);
  return out;
}

std::string vec3(const Eigen::Vector3d& v) { return join({v.x(), v.y(), v.z()}, 4); }

void write_geom(std::ostringstream& out, const Geom& g, const std::string& indent) {
  out << indent << "<geom";
  if (!g.name.empty()) out << " name=\"" << g.name << "\"";
  out << " type=\"" << g.type << "\"";
  if (!g.fromto.empty()) out << " fromto=\"" << join(g.fromto, 4) << "\"";
  else out << " pos=\"" << vec3(g.pos) << "\"";
  out << " size=\"" << join(g.size, 4) << "\"";
  if (g.yaw_rad != 0.0) out << " euler=\"0 0 " << fixed(g.yaw_rad, 5) << "\"";
  out << " group=\"" << g.group << "\" rgba=\"" << g.rgba << "\"/>\n";
}

// Farthest horizontal distance from origin_xy of geom g (world pose in d), sampled exactly enough for primitives.
double horizontal_reach(const mjModel* m, const mjData* d, int g, const Eigen::Vector2d& origin_xy) {
  const Eigen::Vector3d c(d->geom_xpos[3 * g], d->geom_xpos[3 * g + 1], d->geom_xpos[3 * g + 2]);
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) R(r, k) = d->geom_xmat[9 * g + 3 * r + k];
  const double* s = m->geom_size + 3 * g;
  const auto dist = [&](const Eigen::Vector3d& p) { return (p.head<2>() - origin_xy).norm(); };
  double reach = 0;
  switch (m->geom_type[g]) {
    case mjGEOM_BOX:
      for (int corner = 0; corner < 8; ++corner)
        reach = std::max(reach, dist(c + R * Eigen::Vector3d((corner & 1 ? 1 : -1) * s[0], (corner & 2 ? 1 : -1) * s[1],
                                                            (corner & 4 ? 1 : -1) * s[2])));
      break;
    case mjGEOM_CYLINDER:  // the rims of both end discs
      for (int end : {-1, 1})
        for (int k = 0; k < 72; ++k) {
          const double a = k * M_PI / 36;
          reach = std::max(reach, dist(c + R * Eigen::Vector3d(s[0] * std::cos(a), s[0] * std::sin(a), end * s[1])));
        }
      break;
    case mjGEOM_CAPSULE:
      for (int end : {-1, 1}) reach = std::max(reach, dist(c + R * Eigen::Vector3d(0, 0, end * s[1])) + s[0]);
      break;
    case mjGEOM_SPHERE:
      reach = dist(c) + s[0];
      break;
    case mjGEOM_ELLIPSOID:
      reach = dist(c) + std::max({s[0], s[1], s[2]});
      break;
    default:
      reach = dist(c) + m->geom_rbound[g];
  }
  return reach;
}

}  // namespace

std::string fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  std::string out = text;
  if (out.find_first_not_of("-0.") == std::string::npos && out[0] == '-') out.erase(0, 1);
  return out;
}

std::string write_mjcf(const WorldSpec& w) {
  std::ostringstream out;
  const Eigen::Vector2d center = 0.5 * (w.floor_min_W + w.floor_max_W), half = 0.5 * (w.floor_max_W - w.floor_min_W);
  out << "<mujoco model=\"" << w.model_name << "\">\n";
  if (!w.comment.empty()) {
    out << "  <!--\n";
    std::istringstream lines(comment_text(w.comment));
    for (std::string line; std::getline(lines, line);) out << (line.empty() ? "" : "    ") << line << "\n";
    out << "  -->\n";
  }
  out << "  <compiler autolimits=\"true\" angle=\"radian\"/>\n"
      << "  <option timestep=\"0.002\"/>\n"
      << "  <!-- extent 1 makes map znear/zfar absolute: near 0.01 m, far 50 m. -->\n"
      << "  <statistic extent=\"1\" center=\"" << fixed(center.x(), 3) << " " << fixed(center.y(), 3) << " 1.2\"/>\n"
      << "  <visual>\n"
      << "    <quality offsamples=\"0\" shadowsize=\"0\"/>\n"
      << "    <global offwidth=\"1280\" offheight=\"960\"/>\n"
      << "    <map znear=\"0.01\" zfar=\"50\"/>\n"
      << "  </visual>\n"
      << "  <include file=\"robot.xml\"/>\n"
      << "  <worldbody>\n"
      << "    <light name=\"sun\" directional=\"true\" pos=\"0 0 10\" dir=\"0.2 0.1 -1\" castshadow=\"false\"/>\n"
      << "    <geom name=\"floor\" type=\"plane\" pos=\"" << fixed(center.x(), 3) << " " << fixed(center.y(), 3)
      << " 0\" size=\"" << fixed(half.x(), 3) << " " << fixed(half.y(), 3) << " 0.1\" group=\"" << kWallGroup
      << "\" rgba=\"0.5 0.5 0.5 1\"/>\n";
  for (const Body& b : w.bodies) {
    if (!b.comment.empty()) out << "    <!-- " << comment_text(b.comment) << " -->\n";
    out << "    <body name=\"" << b.name << "\" pos=\"" << vec3(b.pos) << "\"";
    if (b.yaw_rad != 0.0) out << " euler=\"0 0 " << fixed(b.yaw_rad, 5) << "\"";
    if (b.mocap) out << " mocap=\"true\"";
    out << ">\n";
    for (const Geom& g : b.geoms) write_geom(out, g, "      ");
    out << "    </body>\n";
  }
  out << "  </worldbody>\n</mujoco>\n";
  return out.str();
}

std::string shipped_robot_xml() { return std::string(STVL_SOURCE_DIR) + "/worlds/robot.xml"; }

double robot_footprint_radius_m(const std::string& robot_xml_path) {
  const sim::World robot = sim::World::from_file(robot_xml_path);
  const mjModel* m = robot.model();
  const int base = mj_name2id(m, mjOBJ_BODY, "base_link");
  if (base < 0) throw std::runtime_error(robot_xml_path + ": no body named base_link");
  const Eigen::Vector2d origin(robot.data()->xpos[3 * base], robot.data()->xpos[3 * base + 1]);
  double radius = 0;
  for (int g = 0; g < m->ngeom; ++g)
    if (m->geom_group[g] == sim::kRobotGeomGroup || m->geom_group[g] == sim::kRobotSeenGeomGroup)
      radius = std::max(radius, horizontal_reach(m, robot.data(), g, origin));
  if (radius <= 0) throw std::runtime_error(robot_xml_path + ": no robot geom (group 2 or 3) to measure the footprint from");
  return radius;
}

}  // namespace stvl::worldgen

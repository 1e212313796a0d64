#include "worldgen/mjcf_writer.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sim/world.hpp"

namespace stvl::worldgen {
namespace {

using robot_description::fixed_numbers;
using robot_description::MjcfWriter;

std::string vec3(const Eigen::Vector3d& v) { return fixed_numbers({v.x(), v.y(), v.z()}, 4); }

void write_geom(MjcfWriter& xml, const Geom& g) {
  xml.open("geom");
  if (!g.name.empty()) xml.attribute("name", g.name);
  xml.attribute("type", g.type);
  if (!g.fromto.empty()) xml.attribute("fromto", fixed_numbers(g.fromto, 4));
  else xml.attribute("pos", vec3(g.pos));
  xml.attribute("size", fixed_numbers(g.size, 4));
  if (g.yaw_rad != 0.0) xml.attribute("euler", "0 0 " + fixed(g.yaw_rad, 5));
  xml.attribute("group", std::to_string(g.group));
  xml.attribute("rgba", g.rgba);
  xml.close();
}

// The header of the shipped worlds: compiler, timestep, statistic, visual, the robot's include.
void write_header(MjcfWriter& xml, const Eigen::Vector2d& center) {
  xml.element("compiler", {{"autolimits", "true"}, {"angle", "radian"}});
  xml.element("option", {{"timestep", "0.002"}});
  xml.comment("extent 1 makes map znear/zfar absolute: near 0.01 m, far 50 m.");
  xml.element("statistic", {{"extent", "1"}, {"center", fixed(center.x(), 3) + " " + fixed(center.y(), 3) + " 1.2"}});
  xml.open("visual");
  xml.element("quality", {{"offsamples", "0"}, {"shadowsize", "0"}});
  xml.element("global", {{"offwidth", "1280"}, {"offheight", "960"}});
  xml.element("map", {{"znear", "0.01"}, {"zfar", "50"}});
  xml.close();
  xml.element("include", {{"file", "robot.xml"}});
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
    case mjGEOM_SPHERE: reach = dist(c) + s[0]; break;
    case mjGEOM_ELLIPSOID: reach = dist(c) + std::max({s[0], s[1], s[2]}); break;
    default: reach = dist(c) + m->geom_rbound[g];
  }
  return reach;
}

}  // namespace

std::string write_mjcf(const WorldSpec& w) {
  MjcfWriter xml(2);
  const Eigen::Vector2d center = 0.5 * (w.floor_min_W + w.floor_max_W), half = 0.5 * (w.floor_max_W - w.floor_min_W);
  xml.open("mujoco");
  xml.attribute("model", w.model_name);
  if (!w.comment.empty()) xml.comment_block(w.comment);
  write_header(xml, center);
  xml.open("worldbody");
  xml.element(
      "light",
      {{"name", "sun"}, {"directional", "true"}, {"pos", "0 0 10"}, {"dir", "0.2 0.1 -1"}, {"castshadow", "false"}});
  xml.element("geom", {{"name", "floor"},
                       {"type", "plane"},
                       {"pos", fixed(center.x(), 3) + " " + fixed(center.y(), 3) + " 0"},
                       {"size", fixed(half.x(), 3) + " " + fixed(half.y(), 3) + " 0.1"},
                       {"group", std::to_string(kWallGroup)},
                       {"rgba", "0.5 0.5 0.5 1"}});
  for (const Body& b : w.bodies) {
    if (!b.comment.empty()) xml.comment(b.comment);
    xml.open("body");
    xml.attribute("name", b.name);
    xml.attribute("pos", vec3(b.pos));
    if (b.yaw_rad != 0.0) xml.attribute("euler", "0 0 " + fixed(b.yaw_rad, 5));
    if (b.mocap) xml.attribute("mocap", "true");
    xml.end_attributes();  // <body ...></body> even without geoms
    for (const Geom& g : b.geoms) write_geom(xml, g);
    xml.close();
  }
  xml.close();
  xml.close();
  return xml.text();
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
  if (radius <= 0)
    throw std::runtime_error(robot_xml_path + ": no robot geom (group 2 or 3) to measure the footprint from");
  return radius;
}

}  // namespace stvl::worldgen

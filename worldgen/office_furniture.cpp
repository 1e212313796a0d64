#include "worldgen/office_furniture.hpp"

#include <cmath>

namespace stvl::worldgen {
namespace {

const char* const kWood = "0.6 0.45 0.3 1";
const char* const kMetal = "0.3 0.3 0.3 1";
const char* const kCardboard = "0.7 0.55 0.35 1";

Geom box(const Eigen::Vector3d& pos, double hx, double hy, double hz, const char* rgba, double yaw = 0) {
  return {"box", "", pos, {hx, hy, hz}, {}, yaw, kObstacleGroup, rgba};
}
Geom cylinder(const Eigen::Vector3d& pos, double r, double hz, const char* rgba) {
  return {"cylinder", "", pos, {r, hz}, {}, 0, kObstacleGroup, rgba};
}
Geom capsule(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r, const char* rgba) {
  return {"capsule",      "",  Eigen::Vector3d::Zero(), {r}, {a.x(), a.y(), a.z(), b.x(), b.y(), b.z()}, 0,
          kObstacleGroup, rgba};
}

Item desk(Rng& rng, Body& b) {
  const double w = rng.snapped(1.2, 1.6, 0.1), d = rng.snapped(0.6, 0.8, 0.05), h = 0.74;
  b.geoms.push_back(box({0, 0, h - 0.015}, w / 2, d / 2, 0.015, kWood));
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0})
      b.geoms.push_back(
          box({sx * (w / 2 - 0.05), sy * (d / 2 - 0.05), (h - 0.03) / 2}, 0.02, 0.02, (h - 0.03) / 2, kMetal));
  b.geoms.push_back(box({0, -(d / 2 - 0.03), 0.45}, w / 2 - 0.08, 0.01, 0.2, "0.55 0.4 0.3 1"));  // modesty panel
  if (rng.chance(0.7)) {                                                                          // a monitor on a foot
    const double x = rng.snapped(-w / 4, w / 4, 0.05);
    b.geoms.push_back(cylinder({x, -(d / 2 - 0.15), h + 0.06}, 0.02, 0.06, kMetal));
    b.geoms.push_back(box({x, -(d / 2 - 0.15), h + 0.3}, 0.27, 0.02, 0.17, "0.1 0.1 0.12 1"));
  }
  return {ItemKind::kDesk, {}, {w / 2, d / 2}, 0};
}

Item shelf(Rng& rng, Body& b) {
  const double w = rng.snapped(0.8, 1.2, 0.1), d = 0.35, h = rng.snapped(1.5, 2.0, 0.1);
  const char* rgba = "0.7 0.6 0.45 1";
  for (double sx : {-1.0, 1.0}) b.geoms.push_back(box({sx * (w / 2 - 0.01), 0, h / 2}, 0.01, d / 2, h / 2, rgba));
  b.geoms.push_back(box({0, -(d / 2 - 0.005), h / 2}, w / 2, 0.005, h / 2, rgba));
  const int boards = rng.integer(4, 5);
  for (int k = 0; k < boards; ++k)
    b.geoms.push_back(box({0, 0.005, 0.05 + k * (h - 0.1) / (boards - 1)}, w / 2 - 0.02, d / 2 - 0.005, 0.01, rgba));
  return {ItemKind::kShelf, {}, {w / 2, d / 2}, 0};
}

Item cart(Rng& rng, Body& b) {
  const double hx = 0.4, hy = 0.25;
  const char* metal = "0.6 0.6 0.65 1";
  for (double z : {0.15, 0.8}) b.geoms.push_back(box({0, 0, z}, hx, hy, 0.015, metal));
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0}) {
      b.geoms.push_back(box({sx * (hx - 0.02), sy * (hy - 0.02), 0.475}, 0.015, 0.015, 0.325, metal));
      b.geoms.push_back({"sphere",
                         "",
                         Eigen::Vector3d(sx * (hx - 0.07), sy * (hy - 0.06), 0.05),
                         {0.05},
                         {},
                         0,
                         kObstacleGroup,
                         "0.1 0.1 0.1 1"});
    }
  b.geoms.push_back(capsule({-hx - 0.02, -hy + 0.03, 0.8}, {-hx - 0.02, -hy + 0.03, 1.0}, 0.015, metal));
  b.geoms.push_back(capsule({-hx - 0.02, hy - 0.03, 0.8}, {-hx - 0.02, hy - 0.03, 1.0}, 0.015, metal));
  b.geoms.push_back(capsule({-hx - 0.02, -hy + 0.03, 1.0}, {-hx - 0.02, hy - 0.03, 1.0}, 0.015, metal));
  if (rng.chance(0.6))
    b.geoms.push_back(box({0.1, 0, 0.165 + 0.12}, 0.18, 0.14, 0.12, kCardboard, rng.uniform(-0.3, 0.3)));
  return {ItemKind::kCart, {}, {hx + 0.04, hy + 0.01}, 0};
}

Item plant(Rng& rng, Body& b) {
  const double r = rng.snapped(0.14, 0.2, 0.01), hz = rng.snapped(0.15, 0.22, 0.01), rz = rng.snapped(0.3, 0.45, 0.01);
  b.geoms.push_back(cylinder({0, 0, hz}, r, hz, "0.45 0.3 0.2 1"));
  b.geoms.push_back({"ellipsoid",
                     "",
                     Eigen::Vector3d(0, 0, 2 * hz + 0.8 * rz),
                     {r + 0.08, r + 0.08, rz},
                     {},
                     0,
                     kObstacleGroup,
                     "0.2 0.5 0.2 1"});
  return {ItemKind::kPlant, {}, {r + 0.08, r + 0.08}, r + 0.08};
}

Item extinguisher(Body& b) {
  // Wall-mounted: the bracket against the wall (y = -0.09), the tank in front of it at 0.6 to 1.1 m.
  b.geoms.push_back(box({0, -0.075, 0.9}, 0.05, 0.015, 0.12, kMetal));
  b.geoms.push_back(cylinder({0, 0.01, 0.85}, 0.08, 0.25, "0.8 0.05 0.05 1"));
  b.geoms.push_back(cylinder({0, 0.01, 1.14}, 0.025, 0.04, "0.2 0.2 0.2 1"));
  return {ItemKind::kExtinguisher, {}, {0.08, 0.09}, 0};
}

// The person of worlds/office_corridor.xml: facing +x, 1.75 m tall.
Item person(Body& b) {
  const auto part = [&](const char* what, Geom g) {
    g.name = b.name + "_" + what;
    b.geoms.push_back(g);
  };
  const char* trousers = "0.2 0.2 0.4 1";
  const char* shirt = "0.6 0.2 0.2 1";
  part("leg_l", capsule({0, 0.1, 0.07}, {0, 0.1, 0.82}, 0.07, trousers));
  part("leg_r", capsule({0, -0.1, 0.07}, {0, -0.1, 0.82}, 0.07, trousers));
  part("torso", capsule({0, 0, 0.95}, {0, 0, 1.38}, 0.17, shirt));
  part("arm_l", capsule({0, 0.23, 0.82}, {0, 0.23, 1.42}, 0.05, shirt));
  part("arm_r", capsule({0, -0.23, 0.82}, {0, -0.23, 1.42}, 0.05, shirt));
  part("head", {"sphere", "", Eigen::Vector3d(0, 0, 1.64), {0.11}, {}, 0, kObstacleGroup, "0.9 0.75 0.6 1"});
  b.mocap = true;
  return {ItemKind::kPerson, {}, {0.3, 0.3}, 0.3};
}

}  // namespace

Item make_item(ItemKind kind, const std::string& name, Rng& rng) {
  Body b;
  b.name = name;
  Item item;
  switch (kind) {
    case ItemKind::kDesk: item = desk(rng, b); break;
    case ItemKind::kShelf: item = shelf(rng, b); break;
    case ItemKind::kCart: item = cart(rng, b); break;
    case ItemKind::kPlant: item = plant(rng, b); break;
    case ItemKind::kExtinguisher: item = extinguisher(b); break;
    case ItemKind::kPerson: item = person(b); break;
    case ItemKind::kCabinet: {
      const double w = rng.snapped(0.6, 1.0, 0.1), d = 0.45, h = rng.snapped(0.75, 1.4, 0.05);
      b.geoms.push_back(box({0, 0, h / 2}, w / 2, d / 2, h / 2, "0.5 0.55 0.6 1"));
      item = {kind, {}, {w / 2, d / 2}, 0};
      break;
    }
    case ItemKind::kBoxes: {  // a cardboard box, sometimes a smaller one on top, each turned a little
      const double hx = rng.snapped(0.15, 0.3, 0.01), hy = rng.snapped(0.12, 0.25, 0.01),
                   hz = rng.snapped(0.1, 0.25, 0.01);
      b.pos.z() = hz;
      b.yaw_rad = rng.uniform(-0.25, 0.25);
      b.geoms.push_back(box({0, 0, 0}, hx, hy, hz, kCardboard));
      item = {kind, {b}, {hx + 0.08, hy + 0.08}, 0};
      if (rng.chance(0.5)) {
        Body top;
        top.name = name + "_top";
        const double tz = rng.snapped(0.08, 0.15, 0.01);
        top.pos = {0, 0, 2 * hz + tz};
        top.yaw_rad = rng.uniform(-0.4, 0.4);
        top.geoms.push_back(box({0, 0, 0}, 0.7 * hx, 0.7 * hy, tz, kCardboard));
        item.bodies.push_back(top);
      }
      return item;
    }
  }
  item.bodies = {b};
  return item;
}

Shape footprint(const Item& item, const Eigen::Vector2d& center_W, double yaw_rad) {
  return item.radius_m > 0 ? Shape::disc(center_W, item.radius_m) : Shape::box(center_W, item.half, yaw_rad);
}

std::vector<Body> placed(const Item& item, const Eigen::Vector2d& center_W, double yaw_rad) {
  std::vector<Body> out = item.bodies;
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  for (Body& b : out) {
    const Eigen::Vector3d local = b.pos;
    b.pos = {center_W.x() + c * local.x() - s * local.y(), center_W.y() + s * local.x() + c * local.y(), local.z()};
    b.yaw_rad = std::remainder(b.yaw_rad + yaw_rad, 2 * M_PI);
  }
  return out;
}

double yaw_facing(const Eigen::Vector2d& facing) { return std::atan2(-facing.x(), facing.y()); }

}  // namespace stvl::worldgen

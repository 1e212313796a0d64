#pragma once
// The things a generated office holds, each built from primitive geoms (box, cylinder, sphere, capsule,
// ellipsoid: the ones ground truth voxelizes exactly) in group 1, in its own frame: origin on the floor at the
// middle of its footprint, x along the wall it stands against, +y facing away from that wall.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "worldgen/mjcf_writer.hpp"
#include "worldgen/office_layout.hpp"
#include "worldgen/rng.hpp"

namespace stvl::worldgen {

enum class ItemKind { kDesk, kCabinet, kShelf, kBoxes, kCart, kPlant, kExtinguisher, kPerson };

// One placeable thing: its bodies (several for a stack of boxes) in the item's frame, and its footprint.
struct Item {
  ItemKind kind = ItemKind::kCabinet;
  std::vector<Body> bodies;                        // pos and yaw in the item's frame
  Eigen::Vector2d half = Eigen::Vector2d::Zero();  // footprint half extents (x along the wall, y depth)
  double radius_m = 0;                             // > 0: a round footprint (plants, people)
};

// A new item of that kind with sizes drawn from rng; its bodies are named `name` (stacks: name, then name_top).
Item make_item(ItemKind kind, const std::string& name, Rng& rng);

// The item's footprint at center_W turned by yaw_rad.
Shape footprint(const Item& item, const Eigen::Vector2d& center_W, double yaw_rad);

// The item's bodies moved to center_W, turned by yaw_rad (people become mocap bodies).
std::vector<Body> placed(const Item& item, const Eigen::Vector2d& center_W, double yaw_rad);

// The yaw that turns an item's +y onto `facing` (a unit vector).
double yaw_facing(const Eigen::Vector2d& facing);

}  // namespace stvl::worldgen

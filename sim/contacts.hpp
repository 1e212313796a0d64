#pragma once
// What the robot touches (issue 31: a robot that stops short is diagnosed "blocked", where and by what).
#include <string>
#include <vector>

#include "sim/world.hpp"

namespace stvl::sim {

// Names of the bodies (a geom's name for geoms of the world body) in contact with any body of the tree rooted
// at robot_body_id, as of the last step; the floor (plane geoms) and the robot's own parts are left out. Sorted,
// each once.
std::vector<std::string> robot_contacts(const World& world, int robot_body_id);

}  // namespace stvl::sim

#include "sim/contacts.hpp"

#include <algorithm>

#include <mujoco/mujoco.h>

namespace stvl::sim {

std::vector<std::string> robot_contacts(const World& world, int robot_body_id) {
  const mjModel* m = world.model();
  const mjData* d = world.data();
  std::vector<std::string> names;
  if (robot_body_id < 0 || robot_body_id >= m->nbody) return names;
  const int root = m->body_rootid[robot_body_id];
  const auto on_robot = [&](int geom) { return m->body_rootid[m->geom_bodyid[geom]] == root; };
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& c = d->contact[i];
    if (on_robot(c.geom1) == on_robot(c.geom2)) continue;  // the robot's own parts, or two other bodies
    const int other = on_robot(c.geom1) ? c.geom2 : c.geom1;
    if (m->geom_type[other] == mjGEOM_PLANE) continue;  // the floor it drives on
    const int body = m->geom_bodyid[other];
    const char* name = body == 0 ? mj_id2name(m, mjOBJ_GEOM, other) : mj_id2name(m, mjOBJ_BODY, body);
    names.push_back(name ? name : (body == 0 ? "geom " : "body ") + std::to_string(body == 0 ? other : body));
  }
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  return names;
}

}  // namespace stvl::sim

#pragma once
#include <string>

#include "sim/world.hpp"

namespace stvl::sim::test {

inline const std::string kWorldsDir = std::string(STVL_SOURCE_DIR) + "/worlds";

// The shipped robot on an empty floor.
inline const char* kFlatWorld = R"(
<mujoco>
  <compiler autolimits="true"/>
  <option timestep="0.002"/>
  <include file="robot.xml"/>
  <worldbody>
    <geom name="floor" type="plane" size="30 30 0.1"/>
  </worldbody>
</mujoco>)";

inline World flat_world() { return World::from_string(kFlatWorld, kWorldsDir); }

}  // namespace stvl::sim::test

#pragma once
// nav2's two costmaps around the 3D layer (Costmap2DROS + LayeredCostmap, navigation2 jazzy f4108e5), each with its
// clock (update_frequency) and its inflation layer:
//   local:  a rolling window (width x height, its origin moved by whole cells to keep the robot in the middle), the
//           layer's cells combined with updateWithMax, then inflation;
//   global: the static map's grid (StaticLayer: the building as a mapping run left it), the layer's cells combined
//           with updateWithMax, then inflation.
// Each costmap reads its own 3D layer's grid (run/closed_loop: STVL runs one instance per costmap, fed the same
// observations, as nav2 does; the bench's nav2 layers keep one window both read). Inflation is recomputed over the
// whole grid at each update (nav2: inside the bounds grown by the inflation radius; cells beyond keep what they had).
#include <Eigen/Core>

#include "mapping/costmap.hpp"
#include "navigation/config.hpp"

namespace stvl::navigation {

// StaticLayer::processMap and interpretValue (nav2_costmap_2d/plugins/static_layer.cpp, jazzy f4108e5) with
// nav2's defaults (lethal_cost_threshold 100, unknown_cost_value -1, trinary_costmap true): 100 -> LETHAL 254,
// -1 -> NO_INFORMATION 255 with track_unknown_space (FREE 0 without), anything else FREE. The grid takes the map's
// size, resolution and origin, as a non-rolling costmap's master does (its origin yaw is not read, as nav2's).
mapping::Costmap2D static_layer_costmap(const OccupancyMap& map, bool track_unknown_space);

class NavCostmap {
 public:
  // Rolling (params.rolling_window): a width x height window; otherwise base_map's grid (the static layer) with
  // base_map's cells under the layer. inscribed_radius_m: the footprint's, for the inflation. Throws
  // std::invalid_argument for a window of no cells or a static map of another resolution.
  NavCostmap(const CostmapParams& params, double inscribed_radius_m, mapping::Costmap2D base_map = {});

  // Whether an update is due at time_s (the first one always; then every 1 / update_frequency).
  bool due(double time_s) const;
  // One update at time_s: the window to the robot (rolling), the base (default or static map), the layer's cells
  // combined (updateWithMax: the layer's NO_INFORMATION skipped), inflation.
  // layer_current: the 3D layer's isCurrent at this update (Layer::current), nav2's costmap isCurrent until the next.
  void update(double time_s, const mapping::Costmap2D& layer_W, const Eigen::Vector2d& robot_W,
              bool layer_current = true);
  // LayeredCostmap::isCurrent: every layer current at the last update (the static and inflation layers always are).
  bool current() const { return current_; }
  // ClearEntireCostmap: every layer reset (the static layer's cells come back), then inflation. Not current until the
  // next update, which is whatever the 3D layer's buffers say (its was_reset_ and the static layer's reset: both
  // current again at their next updateCosts; obstacle_layer.cpp, static_layer.cpp, STVL's reset, at f4108e5).
  void clear();

  // The costmap the planner, controller and behaviours read (inflated), and its combined layers before inflation.
  const mapping::Costmap2D& costmap() const { return inflated_; }
  const mapping::Costmap2D& combined() const { return combined_; }
  const CostmapParams& params() const { return params_; }
  double updated_at_s() const { return updated_at_s_; }

 private:
  void reset_to_base();
  void inflate_now();

  CostmapParams params_;
  double inscribed_radius_m_;
  mapping::Costmap2D base_, combined_, inflated_;
  std::uint8_t default_value_;
  double updated_at_s_ = -1;
  bool current_ = true;
  bool was_reset_ = false;  // cleared since the last update
  long updates_ = 0;
};

}  // namespace stvl::navigation

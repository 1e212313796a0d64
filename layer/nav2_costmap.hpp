#pragma once
// nav2's master costmap fed by a layer (STVL's today), as nav2_costmap_2d and STVL compute it each cycle (STVL
// #199): LayeredCostmap::updateMap moves the rolling window to the robot (Costmap2D::updateOrigin: whole
// cells, the overlap kept, new cells the default), collects the layer's bounds, resets the master only inside
// them (resetMap) and combines the layer there (CostmapLayer::updateWithMax, combination_method 1, or
// updateWithOverwrite, 0). STVL's layer rebuilds its own grid every cycle (resetMaps, then LETHAL where a column
// counts >= mark_threshold, footprint freed) but touches the bounds only at its lethal columns, at the cells of
// the voxels it removed this cycle (PR #200/#203 for #199, 2021-05; off: touch_cleared_cells false, STVL before)
// and at the footprint's vertices. A master cell outside every bound keeps its old value: a ghost when STVL's
// layer no longer has it.
#include <Eigen/Core>

#include <vector>

#include "mapping/costmap.hpp"

namespace stvl::layer {

struct Nav2CostmapConfig {
  double width_m = 0.0;              // YAML map.nav2_costmap.width_m (nav2's width); 0: not modelled
  double height_m = 0.0;             // height_m
  double resolution_m = 0.05;        // resolution_m
  bool rolling_window = true;        // rolling_window
  int combination_method = 1;        // combination_method: 1 max, 0 overwrite (STVL's key)
  bool track_unknown_space = false;  // track_unknown_space: the default cell NO_INFORMATION instead of FREE
  bool touch_cleared_cells = true;   // touch_cleared_cells: STVL since #200/#203; false models STVL before (#199)
  bool enabled() const { return width_m > 0.0 && height_m > 0.0; }
  void validate() const;  // throws std::invalid_argument naming the key
};

// The master's ghosts over a run: after each update, the cells lethal in the master where the layer is not
// (STVL #199).
struct Nav2Ghosts {
  std::size_t updates = 0, updates_with_ghosts = 0, max_cells = 0, last_cells = 0;
  double max_at_s = 0.0;  // the first update with max_cells
};

class Nav2Costmap {
 public:
  // The window starts at the origin; the first update() moves it to the robot (rolling) or leaves it there.
  explicit Nav2Costmap(const Nav2CostmapConfig& config);

  // Moves the window so that the robot at robot_W is in its middle (rolling window; nav2 first, then STVL's own
  // grid, by the same whole cells) and returns the layer's empty grid there: origin, size, resolution.
  mapping::Costmap2D window_at(const Eigen::Vector2d& robot_W);
  // One cycle after window_at(): layer is STVL's grid on that window (kCostLethal where a column counts, the
  // footprint freed, the rest free); cleared_W the x, y of every voxel the update removed; footprint_W the
  // footprint's vertices (empty without update_footprint_enabled).
  void update(const mapping::Costmap2D& layer, const std::vector<Eigen::Vector2d>& cleared_W,
              const std::vector<Eigen::Vector2d>& footprint_W);
  // One cycle of a nav2 layer after window_at(): resetMap of the master over [x0, xn) x [y0, yn) (cells), then the
  // layer's updateCosts with its own grid (the window's size, row by row): combination_method 0
  // (updateWithOverwrite), 1 (updateWithMax) or 2 (updateWithMaxWithoutUnknownOverwrite); all skip the layer's
  // NO_INFORMATION. Throws std::invalid_argument for a grid of another size or another method.
  void combine(const std::vector<std::uint8_t>& layer_cells, int x0, int y0, int xn, int yn, int combination_method);
  // resetLayers' master: every cell back to the default (free, or unknown with track_unknown_space).
  void reset() { master_.cells.assign(master_.cells.size(), default_value_); }
  // The master costmap as the last update left it.
  const mapping::Costmap2D& master() const { return master_; }
  // Master cells lethal where the layer is not: cells nav2 keeps that STVL no longer has (ghosts).
  std::size_t ghost_cells(const mapping::Costmap2D& layer) const;
  const Nav2CostmapConfig& config() const { return config_; }
  // After update(): counts the ghosts against the same layer at time_s into ghosts().
  void count_ghosts(double time_s, const mapping::Costmap2D& layer);
  const Nav2Ghosts& ghosts() const { return ghosts_; }

 private:
  Nav2Ghosts ghosts_;
  Nav2CostmapConfig config_;
  mapping::Costmap2D master_;
  std::uint8_t default_value_;
};

}  // namespace stvl::layer

#pragma once
// nav2's InflationLayer on a whole Costmap2D: the cost of a distance (computeCost), the cell radius (cellDistance)
// and the propagation of updateCosts, reproduced from ros-navigation/navigation2 jazzy f4108e5:
//   - nav2_costmap_2d/plugins/inflation_layer.cpp (updateCosts, enqueue, computeCaches, generateIntegerDistances),
//   - nav2_costmap_2d/include/nav2_costmap_2d/inflation_layer.hpp (computeCost, distanceLookup, costLookup),
//   - nav2_costmap_2d/src/costmap_2d.cpp (cellDistance), include/nav2_costmap_2d/cost_values.hpp.
// inflate() is one updateCosts call over the whole grid with fresh state; see inflation.cpp for where nav2's
// propagation gives a cell a farther obstacle than the nearest one (inflate_reference differs there).
#include <cstdint>

#include "mapping/costmap.hpp"

namespace stvl::navigation {

// nav2_costmap_2d/cost_values.hpp INSCRIBED_INFLATED_OBSTACLE.
constexpr std::uint8_t kCostInscribed = 253;

// The inflation_layer plugin's keys with nav2 jazzy's defaults (InflationLayer::onInitialize).
struct InflationParams {
  double inflation_radius_m = 0.55;     // inflation_radius
  double cost_scaling_factor = 10.0;    // cost_scaling_factor
  bool inflate_unknown = false;         // inflate_unknown
  bool inflate_around_unknown = false;  // inflate_around_unknown

  // Throws std::invalid_argument naming the key when inflation_radius or cost_scaling_factor is negative or NaN.
  void validate() const;
  // validate(), and throws std::invalid_argument naming inflation_radius when it is below the inscribed radius
  // (nav2 only logs an error there and inflates anyway) or the inscribed radius is negative or NaN.
  void validate_against(double inscribed_radius_m) const;
};

// Costmap2D::cellDistance: ceil(radius / resolution), at least 0; the cells inflated lie within this many cells.
int inflation_cell_radius(double inflation_radius_m, double resolution_m);

// InflationLayer::computeCost for a distance in cells: 254 at 0, 253 within the inscribed radius, else
// (unsigned char)(252 * exp(-cost_scaling_factor * (distance_cells * resolution_m - inscribed_radius_m))).
// No cut-off at the inflation radius: updateCosts only visits cells within inflation_cell_radius.
std::uint8_t inflation_cost(double distance_cells, double resolution_m, double inscribed_radius_m,
                            const InflationParams& p);

// InflationLayer::updateCosts over the whole grid, in place. Seeds: lethal cells, and unknown ones when
// inflate_around_unknown. Each visited cell gets max(old, cost), except an unknown old cost, which takes the cost when
// inflate_unknown ? cost > 0 : cost >= 253. Nothing happens when the cell radius is 0. Throws like validate_against
// and on a grid whose cells do not match width x height.
void inflate(mapping::Costmap2D& grid, double inscribed_radius_m, const InflationParams& p);

// The plain version: each cell within inflation_cell_radius of a seed (Euclidean, in cells) takes the cost of its
// nearest seed, with inflate's rules. Equal to inflate wherever nav2's propagation finds the nearest seed.
void inflate_reference(mapping::Costmap2D& grid, double inscribed_radius_m, const InflationParams& p);

}  // namespace stvl::navigation

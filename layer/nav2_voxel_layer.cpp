// nav2's VoxelLayer::raytraceFreespace and the marking loop of VoxelLayer::updateBounds, on the Nav2Layer's grids:
// ros-navigation/navigation2 nav2_costmap_2d/plugins/voxel_layer.cpp and include/nav2_costmap_2d/voxel_layer.hpp
// (worldToMap3DFloat, worldToMap3D), jazzy f4108e5 (= main a3a97043 but for the map sizes, see raytrace). The voxel
// layer kept the 3D squared-distance
// marking rule of before #5697 (which changed the ObstacleLayer only).
#include <algorithm>
#include <cmath>

#include "layer/nav2_layer.hpp"

namespace stvl::layer {
namespace {

// The voxel layer's grid geometry: the 2D grid's origin and resolution, origin_z, z_resolution and the sizes.
struct Geometry {
  double origin_x, origin_y, origin_z, resolution, z_resolution;
  unsigned size_x, size_y, size_z;

  // worldToMap3DFloat: real-valued cell coordinates; false below an origin or at or past a far side.
  bool to_map_float(double wx, double wy, double wz, double& mx, double& my, double& mz) const {
    if (wx < origin_x || wy < origin_y || wz < origin_z) return false;
    mx = (wx - origin_x) / resolution;
    my = (wy - origin_y) / resolution;
    mz = (wz - origin_z) / z_resolution;
    return mx < size_x && my < size_y && mz < size_z;
  }
  // worldToMap3D: the cell, truncated.
  bool to_map(double wx, double wy, double wz, unsigned& mx, unsigned& my, unsigned& mz) const {
    if (wx < origin_x || wy < origin_y || wz < origin_z) return false;
    mx = static_cast<unsigned>((wx - origin_x) / resolution);
    my = static_cast<unsigned>((wy - origin_y) / resolution);
    mz = static_cast<unsigned>((wz - origin_z) / z_resolution);
    return mx < size_x && my < size_y && mz < size_z;
  }
};

Geometry geometry_of(const nav2::CellGrid& grid, const nav2::VoxelGrid& voxels, const Nav2LayerParams& p) {
  return {grid.origin_x_m,  grid.origin_y_m,   p.origin_z_m,      grid.resolution_m,
          p.z_resolution_m, grid.size_x_cells, grid.size_y_cells, voxels.size_z_cells()};
}

}  // namespace

void Nav2Layer::voxel_raytrace(const nav2::Nav2Observation& obs, nav2::Bounds& bounds) {
  if (obs.cloud_W.cols() == 0) return;
  const Geometry g = geometry_of(grid_, voxel_grid_, config_.nav2);
  const double ox = obs.origin_W.x(), oy = obs.origin_W.y(), oz = obs.origin_W.z();
  double sensor_x = 0, sensor_y = 0, sensor_z = 0;
  if (!g.to_map_float(ox, oy, oz, sensor_x, sensor_y, sensor_z)) return;  // nav2 warns: the origin is off the map

  // jazzy f4108e5: getSizeInMeters{X,Y} = (size - 1 + 0.5) * resolution (costmap_2d.cpp), getSizeInMetersZ =
  // (size_z - 1 + 0.5) * z_resolution (voxel_layer.hpp): the rays stop half a level under the grid's top. (main since
  // PR #6028 uses size * resolution for all three; the window's origin follows the same X/Y sizes here.)
  const double map_end_x = g.origin_x + (g.size_x - 1 + 0.5) * g.resolution;
  const double map_end_y = g.origin_y + (g.size_y - 1 + 0.5) * g.resolution;
  const double map_end_z = g.origin_z + (g.size_z - 1 + 0.5) * g.z_resolution;
  const unsigned unknown_threshold = static_cast<unsigned>(config_.nav2.unknown_threshold) + nav2::kMaxZCells -
                                     voxel_grid_.size_z_cells();  // onInitialize: += VOXEL_BITS - size_z_
  const auto mark_threshold = static_cast<unsigned>(config_.nav2.mark_threshold);
  const unsigned cell_max = nav2::cell_distance(grid_, obs.raytrace_max_range_m);
  const unsigned cell_min = nav2::cell_distance(grid_, obs.raytrace_min_range_m);

  for (Eigen::Index i = 0; i < obs.cloud_W.cols(); ++i) {
    double wpx = obs.cloud_W(0, i), wpy = obs.cloud_W(1, i), wpz = obs.cloud_W(2, i);
    // The ray stops two cells (xy resolution) short of the point.
    const double distance = std::sqrt((wpx - ox) * (wpx - ox) + (wpy - oy) * (wpy - oy) + (wpz - oz) * (wpz - oz));
    double scaling_fact = 1.0;
    scaling_fact = std::max(std::min(scaling_fact, (distance - 2 * g.resolution) / distance), 0.0);
    wpx = scaling_fact * (wpx - ox) + ox;
    wpy = scaling_fact * (wpy - oy) + oy;
    wpz = scaling_fact * (wpz - oz) + oz;

    const double a = wpx - ox, b = wpy - oy, c = wpz - oz;
    double t = 1.0;
    bool wp_outside = false;
    if (wpz > map_end_z) {  // up to just under the top of the grid
      t = std::max(0.0, std::min(t, (map_end_z - 0.01 - oz) / c));
      wp_outside = true;
    } else if (wpz < g.origin_z) {  // down to the floor
      t = std::min(t, (g.origin_z - oz) / c);
      wp_outside = true;
    }
    if (wpx < g.origin_x) t = std::min(t, (g.origin_x - ox) / a), wp_outside = true;
    if (wpy < g.origin_y) t = std::min(t, (g.origin_y - oy) / b), wp_outside = true;
    if (wpx > map_end_x) t = std::min(t, (map_end_x - ox) / a), wp_outside = true;
    if (wpy > map_end_y) t = std::min(t, (map_end_y - oy) / b), wp_outside = true;
    constexpr double kWpEpsilon = 1e-5;
    if (wp_outside) {
      if (t > 0.0) t -= kWpEpsilon;
      else if (t < 0.0) t += kWpEpsilon;
    }
    wpx = ox + a * t;
    wpy = oy + b * t;
    wpz = oz + c * t;

    double point_x = 0, point_y = 0, point_z = 0;
    if (!g.to_map_float(wpx, wpy, wpz, point_x, point_y, point_z)) continue;
    voxel_grid_.clear_voxel_line_in_map(sensor_x, sensor_y, sensor_z, point_x, point_y, point_z, &grid_.costs,
                                        unknown_threshold, mark_threshold, nav2::kFreeSpace, nav2::kNoInformation,
                                        cell_max, cell_min);
    nav2::update_raytrace_bounds(ox, oy, wpx, wpy, obs.raytrace_max_range_m, obs.raytrace_min_range_m, bounds);
  }
}

void Nav2Layer::voxel_mark(const nav2::Nav2Observation& obs, nav2::Bounds& bounds) {
  const Geometry g = geometry_of(grid_, voxel_grid_, config_.nav2);
  const double sq_max = obs.obstacle_max_range_m * obs.obstacle_max_range_m;
  const double sq_min = obs.obstacle_min_range_m * obs.obstacle_min_range_m;
  const auto mark_threshold = static_cast<unsigned>(config_.nav2.mark_threshold);
  for (Eigen::Index i = 0; i < obs.cloud_W.cols(); ++i) {
    const float x = obs.cloud_W(0, i), y = obs.cloud_W(1, i), z = obs.cloud_W(2, i);
    if (z < config_.nav2.min_obstacle_height_m) continue;  // too low
    if (z > config_.nav2.max_obstacle_height_m) continue;  // too high
    const double dx = x - obs.origin_W.x(), dy = y - obs.origin_W.y(), dz = z - obs.origin_W.z();
    const double sq_dist = dx * dx + dy * dy + dz * dz;
    if (sq_dist >= sq_max) continue;  // too far: a point at the range too
    if (sq_dist < sq_min) continue;   // too close
    unsigned mx = 0, my = 0, mz = 0;
    // A point under origin_z marks the lowest level.
    if (!g.to_map(x, y, z < g.origin_z ? g.origin_z : static_cast<double>(z), mx, my, mz)) continue;
    if (voxel_grid_.mark_voxel_in_map(mx, my, mz, mark_threshold)) {
      grid_.costs[grid_.index(mx, my)] = nav2::kLethalObstacle;
      bounds.touch(x, y);
    }
  }
}

std::vector<VoxelKey> Nav2Layer::marked_keys() const {
  std::vector<VoxelKey> keys;
  const double r = grid_.resolution_m, zr = config_.nav2.z_resolution_m, oz = config_.nav2.origin_z_m;
  for (unsigned y = 0; y < grid_.size_y_cells; ++y)
    for (unsigned x = 0; x < grid_.size_x_cells; ++x) {
      const std::uint32_t column = voxel_grid_.column(x, y);
      if ((column >> nav2::kMaxZCells) == 0) continue;  // no marked level
      // The bench's cell holding the nav2 cell's centre (the grids share their xy lines up to rounding).
      const int kx = static_cast<int>(std::floor((grid_.origin_x_m + (x + 0.5) * r) / r));
      const int ky = static_cast<int>(std::floor((grid_.origin_y_m + (y + 0.5) * r) / r));
      for (unsigned z = 0; z < voxel_grid_.size_z_cells(); ++z) {
        if (voxel_grid_.voxel(x, y, z) != nav2::VoxelStatus::kMarked) continue;
        const double lo = oz + z * zr, hi = oz + (z + 1) * zr;
        int k_lo = static_cast<int>(std::ceil(lo / r - 0.5)), k_hi = static_cast<int>(std::ceil(hi / r - 0.5)) - 1;
        if (k_hi < k_lo) k_lo = k_hi = static_cast<int>(std::floor((lo + hi) / 2 / r));
        for (int k = k_lo; k <= k_hi; ++k) keys.push_back({kx, ky, k});
      }
    }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return keys;
}

}  // namespace stvl::layer

#pragma once
// Depth-edge ("flying pixel") filter, the bench's (STVL has none): run on the noisy depth image before depth to cloud.
// A valid pixel is dropped (set to 0) when the depth of any valid pixel of its 8-neighbourhood differs from its
// own depth z by more than
//
//   jump_threshold_m(z) = max_jump_at_1m_m * z^2          (z in m)
//
// Why a depth jump growing with z^2, and not the veiling-point angle test of laser_filters / PCL's ShadowPoints
// (drop a point when the line to its neighbour is within some angle of the viewing ray, i.e. a jump above
// z / (f * tan(angle)), linear in z): a stereo camera's depth noise grows with z^2 (sigma_z = z^2 * subpixel /
// (f * baseline), sensors/depth_noise.hpp), so a threshold linear in z falls below the noise of neighbouring
// pixels beyond a metre or two and thins flat surfaces; one growing with z^2 stays the same number of sigmas at
// every depth (default 0.03 m at 1 m: 8 sigma of the D435 model at fx 433 px, baseline 0.05 m, subpixel 0.08,
// and 5.7 sigma of the difference of two pixels; another camera's 8 sigma is 8 * subpixel / (fx * baseline)).
// The geometry of a plane scales the same way: neighbouring pixels on a plane at perpendicular distance d from
// the optical centre differ by at most about z^2 / (f * d) (sqrt(2) times that diagonally), so the filter thins
// only planes passing within about sqrt(2) / (f * max_jump_at_1m_m) of the camera (0.11 m at f = 433 px),
// whatever their depth.
// What it removes: flying pixels (which lie between a foreground and a background surface, far from both) and
// the one-pixel rims on both sides of every depth jump. A pixel kept is within the threshold of every valid
// neighbour. Pixels without a valid neighbour are kept. Invalid pixels (0, negative, NaN, infinite) stay as they are.
#include "sensors/depth_image.hpp"

#include <cstddef>

namespace stvl::sensors {

struct DepthEdgeFilterConfig {
  bool enabled = false;            // off by default: STVL has no such filter
  double max_jump_at_1m_m = 0.03;  // jump threshold at 1 m depth; scales with depth^2

  // Throws std::invalid_argument naming max_jump_at_1m_m when it is not finite or not > 0.
  void validate() const;
  double jump_threshold_m(double z_m) const { return max_jump_at_1m_m * z_m * z_m; }
};

// Writes the filtered image to `out` (resized to the input's size; no allocation once it has that size) and
// returns the number of pixels dropped. `in` and `out` must be distinct. Rows run in parallel (TBB);
// identity copy when config.enabled is false. Its plain twin is sensors/reference/depth_edge_filter.hpp (tests only).
std::size_t filter_depth_edges(const DepthEdgeFilterConfig& config, const DepthImage& in, DepthImage& out);

}  // namespace stvl::sensors

#pragma once
// The plain twin of sensors/depth_edge_filter.hpp: one pass over the pixels on this thread, written from
// filter_depth_edges' comment. tests/sensors compares the two (equal images, bit for bit); linked by tests only.
#include <cstddef>

#include "sensors/depth_edge_filter.hpp"
#include "sensors/depth_image.hpp"

namespace stvl::sensors::reference {

// filter_depth_edges(config, in, out) pixel by pixel: a valid pixel (finite depth z > 0) is dropped (set to 0)
// when one of its 8 neighbours is valid and differs from z by more than max_jump_at_1m_m * z^2 (float
// arithmetic, as the optimized one). Returns the number dropped; `out` becomes a copy of `in` with them at 0.
// Throws std::invalid_argument for an inconsistent image, `in` and `out` the same, or a bad config.
std::size_t filter_depth_edges(const DepthEdgeFilterConfig& config, const DepthImage& in, DepthImage& out);

}  // namespace stvl::sensors::reference

#include "sensors/depth_edge_filter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

namespace stvl::sensors {
namespace {

// The float arithmetic of the plain twin (sensors/reference/), so that their images are equal bit for bit.
inline float threshold_m(float max_jump_at_1m_m, float z_m) { return max_jump_at_1m_m * z_m * z_m; }

// Valid: a finite depth > 0 (0, negative, NaN and infinity are invalid), as depth_to_cloud reads it.
inline bool valid(float z_m) { return (z_m > 0.0f) & (z_m <= std::numeric_limits<float>::max()); }

// True when the neighbour's depth zn is valid and differs from z by more than the threshold.
inline bool jumps(float z_m, float zn_m, float threshold) { return valid(zn_m) & (std::abs(zn_m - z_m) > threshold); }

void check_input(const DepthImage& in, const DepthImage& out) {
  if (in.width < 0 || in.height < 0 || in.depth_m.size() != size_t(in.width) * size_t(in.height))
    throw std::invalid_argument("filter_depth_edges: image " + std::to_string(in.width) + "x" +
                                std::to_string(in.height) + " holds " + std::to_string(in.depth_m.size()) + " values");
  if (&in == &out) throw std::invalid_argument("filter_depth_edges: input and output are the same image");
}

void resize_like(const DepthImage& in, DepthImage& out) {
  out.width = in.width;
  out.height = in.height;
  out.depth_m.resize(in.depth_m.size());
}

}  // namespace

void DepthEdgeFilterConfig::validate() const {
  if (!(std::isfinite(max_jump_at_1m_m) && max_jump_at_1m_m > 0.0))
    throw std::invalid_argument("DepthEdgeFilterConfig: max_jump_at_1m_m " + std::to_string(max_jump_at_1m_m) +
                                " must be finite and > 0 m");
}

namespace {

// Whether pixel (u, v) of the W x H image `src` is dropped, with bounds tests (the border's path).
inline bool drops_checked(const float* src, int W, int H, float c, int u, int v) {
  const float z = src[size_t(v) * W + u];
  if (!valid(z)) return false;
  const float t = threshold_m(c, z);
  for (int dv = -1; dv <= 1; ++dv)
    for (int du = -1; du <= 1; ++du) {
      const int uu = u + du, vv = v + dv;
      if ((du == 0 && dv == 0) || uu < 0 || vv < 0 || uu >= W || vv >= H) continue;
      if (jumps(z, src[size_t(vv) * W + uu], t)) return true;
    }
  return false;
}

// The interior pixels 1..W-2 of an interior row: their 8 neighbours without bounds tests or branches (a loop the
// compiler vectorizes). Returns the pixels dropped.
inline std::size_t filter_interior_row(const float* row, int W, float c, float* out_row) {
  const float* up = row - W;
  const float* down = row + W;
  std::size_t row_dropped = 0;
  for (int u = 1; u + 1 < W; ++u) {
    const float z = row[u];
    const float t = threshold_m(c, z);
    const bool drop = valid(z) & (jumps(z, row[u - 1], t) | jumps(z, row[u + 1], t) | jumps(z, up[u - 1], t) |
                                  jumps(z, up[u], t) | jumps(z, up[u + 1], t) | jumps(z, down[u - 1], t) |
                                  jumps(z, down[u], t) | jumps(z, down[u + 1], t));
    out_row[u] = drop ? 0.0f : z;
    row_dropped += drop;
  }
  return row_dropped;
}

// Rows [begin, end) of src into dst; every output pixel reads the input only. Returns the pixels dropped.
inline std::size_t filter_rows(const float* src, float* dst, int W, int H, float c, int begin, int end) {
  std::size_t dropped = 0;
  for (int v = begin; v < end; ++v) {
    const float* row = src + size_t(v) * W;
    float* out_row = dst + size_t(v) * W;
    if (v == 0 || v + 1 == H || W < 3) {  // the border rows take the checked path
      for (int u = 0; u < W; ++u) {
        const bool drop = drops_checked(src, W, H, c, u, v);
        out_row[u] = drop ? 0.0f : row[u];
        dropped += drop;
      }
      continue;
    }
    for (int u : {0, W - 1}) {  // and so do the border columns
      const bool drop = drops_checked(src, W, H, c, u, v);
      out_row[u] = drop ? 0.0f : row[u];
      dropped += drop;
    }
    dropped += filter_interior_row(row, W, c, out_row);
  }
  return dropped;
}

}  // namespace

std::size_t filter_depth_edges(const DepthEdgeFilterConfig& config, const DepthImage& in, DepthImage& out) {
  check_input(in, out);
  config.validate();
  resize_like(in, out);
  if (!config.enabled) {
    std::copy(in.depth_m.begin(), in.depth_m.end(), out.depth_m.begin());
    return 0;
  }
  const int W = in.width, H = in.height;
  const float c = float(config.max_jump_at_1m_m);
  const float* src = in.depth_m.data();
  float* dst = out.depth_m.data();
  // Rows in parallel (blocks of 16), the dropped pixels summed.
  const auto rows = [&](const tbb::blocked_range<int>& range, std::size_t dropped) {
    return dropped + filter_rows(src, dst, W, H, c, range.begin(), range.end());
  };
  return tbb::parallel_reduce(tbb::blocked_range<int>(0, H, 16), std::size_t(0), rows,
                              [](std::size_t a, std::size_t b) { return a + b; });
}

}  // namespace stvl::sensors

#include "sensors/reference/depth_edge_filter.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace stvl::sensors::reference {
namespace {

float threshold_m(float max_jump_at_1m_m, float z_m) { return max_jump_at_1m_m * z_m * z_m; }
bool valid(float z_m) { return z_m > 0.0f && z_m <= std::numeric_limits<float>::max(); }

}  // namespace

std::size_t filter_depth_edges(const DepthEdgeFilterConfig& config, const DepthImage& in, DepthImage& out) {
  if (in.width < 0 || in.height < 0 || in.depth_m.size() != size_t(in.width) * size_t(in.height))
    throw std::invalid_argument("reference::filter_depth_edges: image " + std::to_string(in.width) + "x" +
                                std::to_string(in.height) + " holds " + std::to_string(in.depth_m.size()) + " values");
  if (&in == &out) throw std::invalid_argument("reference::filter_depth_edges: input and output are the same image");
  config.validate();
  out = in;
  if (!config.enabled) return 0;
  std::size_t dropped = 0;
  for (int v = 0; v < in.height; ++v) {
    for (int u = 0; u < in.width; ++u) {
      const float z = in.at(u, v);
      if (!valid(z)) continue;
      const float threshold = threshold_m(float(config.max_jump_at_1m_m), z);
      bool drop = false;
      for (int dv = -1; dv <= 1; ++dv)
        for (int du = -1; du <= 1; ++du) {
          const int uu = u + du, vv = v + dv;
          if ((du == 0 && dv == 0) || uu < 0 || vv < 0 || uu >= in.width || vv >= in.height) continue;
          const float zn = in.at(uu, vv);
          if (valid(zn) && std::abs(zn - z) > threshold) drop = true;
        }
      if (drop) {
        out.at(u, v) = 0.0f;
        ++dropped;
      }
    }
  }
  return dropped;
}

}  // namespace stvl::sensors::reference

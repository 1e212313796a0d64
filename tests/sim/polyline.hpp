#pragma once
// Distance from a point to a path's polyline (the kinematic drive's and the URDF robot's tests).
#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <vector>

namespace stvl::test {

// Distance from p to the polyline through w (metres, world x-y).
inline double off_polyline(const std::vector<Eigen::Vector2d>& w, const Eigen::Vector2d& p) {
  double best = INFINITY;
  for (std::size_t i = 1; i < w.size(); ++i) {
    const Eigen::Vector2d d = w[i] - w[i - 1];
    const double t = std::clamp((p - w[i - 1]).dot(d) / d.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (w[i - 1] + t * d - p).norm());
  }
  return best;
}

}  // namespace stvl::test

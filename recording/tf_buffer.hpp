#pragma once
// Poses over time as a recording gives them (not part of the interface, no ROS headers): one pose's time series,
// interpolated without extrapolation, and a small tf buffer of parent links (static edges constant, dynamic
// ones interpolated), for the bag readers.
#include <Eigen/Geometry>

#include <algorithm>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace stvl::recording::detail {

constexpr double kTfTimeTolerance_s = 1e-6;  // stamps this close count as equal

inline Eigen::Isometry3d interpolate(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double w) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = (1 - w) * a.translation() + w * b.translation();
  T.linear() = Eigen::Quaterniond(a.linear()).slerp(w, Eigen::Quaterniond(b.linear())).toRotationMatrix();
  return T;
}

// Time series of one pose, interpolated (linear translation, slerp); no extrapolation.
struct PoseSeries {
  std::vector<std::pair<double, Eigen::Isometry3d>> samples;  // sorted by time after sort()

  void sort() {
    std::stable_sort(samples.begin(), samples.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  }
  // Empty when t lies outside the samples' span.
  std::optional<Eigen::Isometry3d> at(double t) const {
    if (samples.empty() || t < samples.front().first - kTfTimeTolerance_s ||
        t > samples.back().first + kTfTimeTolerance_s) {
      return std::nullopt;
    }
    auto it =
        std::lower_bound(samples.begin(), samples.end(), t, [](const auto& s, double time) { return s.first < time; });
    if (it == samples.end()) return samples.back().second;
    if (it == samples.begin() || it->first - t <= kTfTimeTolerance_s) return it->second;
    const auto& a = *(it - 1);
    const double w = (t - a.first) / (it->first - a.first);
    return interpolate(a.second, it->second, w);
  }
  std::string span() const {
    return "[" + std::to_string(samples.front().first) + ", " + std::to_string(samples.back().first) + "] s";
  }
};

// A small tf buffer: one parent per child frame; static edges constant, dynamic ones interpolated.
struct TfBuffer {
  struct Edge {
    std::string parent;
    bool is_static = false;
    Eigen::Isometry3d T_static = Eigen::Isometry3d::Identity();
    PoseSeries series;
  };
  std::map<std::string, Edge> edges;  // by child

  bool has(const std::string& frame) const {
    if (edges.count(frame)) return true;
    for (const auto& [child, e] : edges)
      if (e.parent == frame) return true;
    return false;
  }
  std::string root_of(std::string frame) const {
    for (std::size_t i = 0; i <= edges.size(); ++i) {
      const auto it = edges.find(frame);
      if (it == edges.end()) return frame;
      frame = it->second.parent;
    }
    throw std::invalid_argument("tf has a cycle through frame '" + frame + "'");
  }
  // Frames from `frame` up to the root, `frame` first.
  std::vector<std::string> chain(std::string frame) const {
    std::vector<std::string> out{frame};
    for (auto it = edges.find(frame); it != edges.end() && out.size() <= edges.size() + 1;
         it = edges.find(it->second.parent)) {
      out.push_back(it->second.parent);
    }
    return out;
  }
  bool links(const std::string& ancestor, const std::string& frame) const {
    const auto c = chain(frame);
    return std::find(c.begin(), c.end(), ancestor) != c.end();
  }
  // T_ancestor_frame at time t; throws naming the edge with no pose at t.
  Eigen::Isometry3d lookup(const std::string& ancestor, const std::string& frame, double t) const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    std::string f = frame;
    while (f != ancestor) {
      const auto it = edges.find(f);
      if (it == edges.end()) {
        throw std::invalid_argument("tf: frame '" + frame + "' is not linked to '" + ancestor + "'");
      }
      const Edge& e = it->second;
      if (e.is_static) {
        T = e.T_static * T;
      } else {
        const auto T_edge = e.series.at(t);
        if (!T_edge) {
          throw std::invalid_argument("no pose at t = " + std::to_string(t) + " s: /tf " + e.parent + " -> " + f +
                                      " covers only " + e.series.span() + " (no extrapolation)");
        }
        T = *T_edge * T;
      }
      f = e.parent;
    }
    return T;
  }
};

}  // namespace stvl::recording::detail

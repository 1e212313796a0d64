#pragma once
// Scripted motion of mocap bodies: keyframes (time -> position, optional yaw), linearly
// interpolated, held constant before the first and after the last keyframe. A repeating track
// (repeat_s) instead goes on from its last keyframe back to its first, reached at t0 + repeat_s, and
// around again: its pose at t + repeat_s equals its pose at t for every t >= t0 (the first keyframe's time).
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "sim/world.hpp"

namespace stvl::sim {

struct MocapKeyframe {
  double time_s = 0.0;
  Eigen::Vector3d position_W = Eigen::Vector3d::Zero();
  std::optional<double> yaw_rad;  // all keyframes of a track set it, or none (orientation kept)
};

struct MocapTrack {
  std::string body;
  std::vector<MocapKeyframe> keyframes;
  std::optional<double> repeat_s = std::nullopt;  // period; at least the track's span (last minus first keyframe time)
};

class MocapScript {
 public:
  MocapScript() = default;
  // Throws std::invalid_argument for unknown or non-mocap bodies, empty tracks, times not
  // strictly increasing, non-finite values, a yaw given on only some keyframes, or a repeat_s that is not
  // finite, not > 0 or shorter than the track's span.
  MocapScript(const World& world, std::vector<MocapTrack> tracks);

  // Writes mocap_pos (and mocap_quat) for time_s; takes effect at the next kinematics pass.
  void apply(const mjModel* model, mjData* data, double time_s) const;
  bool empty() const { return tracks_.empty(); }

 private:
  struct Resolved {
    int mocap_id;
    MocapTrack track;
  };
  std::vector<Resolved> tracks_;
};

}  // namespace stvl::sim

#include "sim/mocap_script.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace stvl::sim {

MocapScript::MocapScript(const World& world, std::vector<MocapTrack> tracks) {
  for (auto& track : tracks) {
    const int body = world.body_id(track.body);
    const int mocap_id = world.model()->body_mocapid[body];
    if (mocap_id < 0) throw std::invalid_argument("body '" + track.body + "' is not a mocap body");
    if (track.keyframes.empty()) throw std::invalid_argument("mocap track '" + track.body + "' has no keyframes");
    const bool has_yaw = track.keyframes.front().yaw_rad.has_value();
    for (std::size_t i = 0; i < track.keyframes.size(); ++i) {
      const auto& k = track.keyframes[i];
      if (!std::isfinite(k.time_s) || !k.position_W.allFinite() || (k.yaw_rad && !std::isfinite(*k.yaw_rad))) {
        throw std::invalid_argument("mocap track '" + track.body + "' keyframe " + std::to_string(i) +
                                    " is not finite");
      }
      if (k.yaw_rad.has_value() != has_yaw) {
        throw std::invalid_argument("mocap track '" + track.body + "': yaw_rad given on some keyframes only");
      }
      if (i > 0 && !(k.time_s > track.keyframes[i - 1].time_s)) {
        throw std::invalid_argument("mocap track '" + track.body + "': keyframe time_s " + std::to_string(k.time_s) +
                                    " not after the previous one");
      }
    }
    if (track.repeat_s) {
      const double span_s = track.keyframes.back().time_s - track.keyframes.front().time_s;
      if (!std::isfinite(*track.repeat_s) || !(*track.repeat_s > 0) || *track.repeat_s < span_s) {
        throw std::invalid_argument("mocap track '" + track.body + "': repeat_s " + std::to_string(*track.repeat_s) +
                                    " must be finite, > 0 and at least the track's span " + std::to_string(span_s) +
                                    " s");
      }
    }
    tracks_.push_back({mocap_id, std::move(track)});
  }
}

void MocapScript::apply(const mjModel* /*model*/, mjData* data, double time_s) const {
  for (const auto& [mocap_id, track] : tracks_) {
    const auto& k = track.keyframes;
    double t_s = time_s;
    if (track.repeat_s && t_s > k.front().time_s) {
      t_s = k.front().time_s + std::fmod(t_s - k.front().time_s, *track.repeat_s);
    }
    const auto next =
        std::upper_bound(k.begin(), k.end(), t_s, [](double t, const MocapKeyframe& f) { return t < f.time_s; });
    Eigen::Vector3d p;
    double yaw = 0.0;
    if (next == k.end() && track.repeat_s && t_s > k.back().time_s) {
      // The closing stretch of a repeating track: from the last keyframe back to the first.
      const MocapKeyframe& a = k.back();
      const MocapKeyframe& b = k.front();
      const double t = (t_s - a.time_s) / (k.front().time_s + *track.repeat_s - a.time_s);
      p = a.position_W + t * (b.position_W - a.position_W);
      if (a.yaw_rad)
        yaw = *a.yaw_rad + t * std::atan2(std::sin(*b.yaw_rad - *a.yaw_rad), std::cos(*b.yaw_rad - *a.yaw_rad));
    } else if (next == k.begin() || next == k.end()) {
      const MocapKeyframe& f = next == k.begin() ? k.front() : k.back();
      p = f.position_W;
      yaw = f.yaw_rad.value_or(0.0);
    } else {
      const MocapKeyframe& a = *(next - 1);
      const MocapKeyframe& b = *next;
      const double t = (t_s - a.time_s) / (b.time_s - a.time_s);
      p = a.position_W + t * (b.position_W - a.position_W);
      if (a.yaw_rad) {
        const double dyaw = std::atan2(std::sin(*b.yaw_rad - *a.yaw_rad), std::cos(*b.yaw_rad - *a.yaw_rad));
        yaw = *a.yaw_rad + t * dyaw;
      }
    }
    for (int i = 0; i < 3; ++i) data->mocap_pos[3 * mocap_id + i] = p[i];
    if (k.front().yaw_rad) {
      data->mocap_quat[4 * mocap_id + 0] = std::cos(0.5 * yaw);
      data->mocap_quat[4 * mocap_id + 1] = 0.0;
      data->mocap_quat[4 * mocap_id + 2] = 0.0;
      data->mocap_quat[4 * mocap_id + 3] = std::sin(0.5 * yaw);
    }
  }
}

}  // namespace stvl::sim

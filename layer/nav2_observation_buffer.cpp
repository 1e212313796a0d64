#include "layer/nav2_observation_buffer.hpp"

#include <algorithm>
#include <utility>

namespace stvl::layer::nav2 {

std::int64_t ros_ns_from_seconds(double seconds) {
  return static_cast<std::int64_t>(seconds * (1000LL * 1000LL * 1000LL));  // RCL_S_TO_NS on a double
}

Nav2ObservationBuffer::Nav2ObservationBuffer(const Nav2SourceParams& params, std::int64_t created_ns, PurgeRule rule)
    : params_(params),
      keep_ns_(ros_ns_from_seconds(params.observation_persistence_s)),
      expected_update_rate_ns_(ros_ns_from_seconds(params.expected_update_rate_s)),
      last_updated_ns_(created_ns),
      rule_(rule) {}

void Nav2ObservationBuffer::buffer_cloud(const Eigen::Vector3d& origin_W, const Eigen::Matrix3Xf& cloud_W,
                                         std::int64_t stamp_ns, std::int64_t now_ns) {
  auto obs = std::make_shared<Nav2Observation>();
  obs->origin_W = origin_W;
  obs->stamp_ns = stamp_ns;
  obs->obstacle_max_range_m = params_.obstacle_max_range_m;
  obs->obstacle_min_range_m = params_.obstacle_min_range_m;
  obs->raytrace_max_range_m = params_.raytrace_max_range_m;
  obs->raytrace_min_range_m = params_.raytrace_min_range_m;

  // The source's band, both ends kept; z is the cloud's float, the limits double.
  std::vector<Eigen::Index> kept;
  for (Eigen::Index i = 0; i < cloud_W.cols(); ++i) {
    const float z = cloud_W(2, i);
    if (z <= params_.max_obstacle_height_m && z >= params_.min_obstacle_height_m) kept.push_back(i);
  }
  obs->cloud_W.resize(3, static_cast<Eigen::Index>(kept.size()));
  for (std::size_t k = 0; k < kept.size(); ++k) obs->cloud_W.col(static_cast<Eigen::Index>(k)) = cloud_W.col(kept[k]);

  list_.push_front(std::move(obs));
  last_updated_ns_ = now_ns;
  purge_stale(now_ns);
}

void Nav2ObservationBuffer::get_observations(std::int64_t now_ns,
                                             std::vector<std::shared_ptr<const Nav2Observation>>& out) {
  purge_stale(now_ns);
  out.insert(out.end(), list_.begin(), list_.end());
}

void Nav2ObservationBuffer::purge_stale(std::int64_t now_ns) {
  if (list_.empty()) return;
  if (keep_ns_ == 0) {
    list_.resize(1);
    return;
  }
  const auto stale = [&](const std::shared_ptr<const Nav2Observation>& o) { return now_ns - o->stamp_ns > keep_ns_; };
  if (rule_ == PurgeRule::kJazzy) {
    list_.erase(std::find_if(list_.begin(), list_.end(), stale), list_.end());
  } else {
    list_.erase(std::remove_if(list_.begin(), list_.end(), stale), list_.end());
  }
}

bool Nav2ObservationBuffer::is_current(std::int64_t now_ns) const {
  if (expected_update_rate_ns_ == 0) return true;
  return now_ns - last_updated_ns_ <= expected_update_rate_ns_;
}

}  // namespace stvl::layer::nav2

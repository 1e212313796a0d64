#pragma once
// nav2's ObservationBuffer without tf (nav2_costmap_2d/src/observation_buffer.cpp, ros-navigation/navigation2 jazzy
// f4108e5; main a3a9704 where said): the clouds one observation source keeps for the obstacle and voxel layers.
// Times are rclcpp's: integer nanoseconds (rclcpp::Duration::from_seconds truncates s * 1e9), compared exactly.
//   - bufferCloud: the cloud, already in the global frame, keeps the points with min_obstacle_height <= z <=
//     max_obstacle_height (the source's band, inclusive, float z against double limits); the observation stores
//     the sensor origin and the source's four ranges; it goes to the front; last_updated becomes *now* (the
//     reception, not the stamp); then the stale ones are purged at now.
//   - purgeStaleObservations at now: a keep time (observation_persistence) of 0 ns keeps the front one only
//     (any keep time under 1 ns is 0 ns); otherwise an observation is stale when now - stamp > keep time
//     (strictly; a negative keep time makes every one stale, the new one too). Jazzy erases from the first stale
//     one (front to back) to the end; main since ebe9d7c (#4890) removes the stale ones only (remove_if). They
//     differ only when stamps arrive out of order.
//   - getObservations at now: purges, then appends the observations front (last received) to back.
//   - isCurrent at now: true when expected_update_rate is 0 ns, else now - last_updated <= rate (last_updated
//     starts at the buffer's creation).
// Against STVL's buffer (layer/source_buffer.hpp): STVL ages readings from the last reading's stamp and purges only
// when one arrives, so a stopped camera's last observation_persistence seconds stay applied; nav2 ages them from
// now and purges at every update too, so they expire. STVL's current/last_updated is the reading's stamp, nav2's the
// reception time. Both keep only the newest at persistence 0 and compare the rate with <=. nav2 filters z in the
// global frame here (STVL's height band is its passthrough, source_marking_W), and STVL has no ranges per reading.
#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include <Eigen/Core>

namespace stvl::layer::nav2 {

// rclcpp::Duration::from_seconds: static_cast<int64_t>(seconds * 1e9), truncated toward zero.
std::int64_t ros_ns_from_seconds(double seconds);

// One observation source's parameters, with ObstacleLayer's defaults (onInitialize, jazzy f4108e5).
struct Nav2SourceParams {
  double observation_persistence_s = 0.0;  // observation_persistence: the buffer's keep time
  double expected_update_rate_s = 0.0;     // expected_update_rate: a period; 0 = always current
  double min_obstacle_height_m = 0.0;      // min_obstacle_height: the buffer's band, in the global frame
  double max_obstacle_height_m = 0.0;      // max_obstacle_height: 0 by default, so it must be set
  double obstacle_max_range_m = 2.5, obstacle_min_range_m = 0.0;  // obstacle_max_range / obstacle_min_range
  double raytrace_max_range_m = 3.0, raytrace_min_range_m = 0.0;  // raytrace_max_range / raytrace_min_range
  bool marking = true, clearing = false;                          // marking / clearing
};

// nav2's Observation: the kept points, the sensor origin, the source's ranges, the cloud's stamp.
struct Nav2Observation {
  Eigen::Vector3d origin_W = Eigen::Vector3d::Zero();  // the sensor frame's origin in the global frame
  Eigen::Matrix3Xf cloud_W;                            // the points inside the band, global frame, as received
  std::int64_t stamp_ns = 0;                           // the cloud's header stamp
  double obstacle_max_range_m = 0, obstacle_min_range_m = 0, raytrace_max_range_m = 0, raytrace_min_range_m = 0;
};

// Which purge rule: jazzy's (erase from the first stale one) or main's (remove each stale one).
enum class PurgeRule { kJazzy, kMain };

class Nav2ObservationBuffer {
 public:
  // Empty; last updated at created_ns (the node's clock when the layer made it).
  Nav2ObservationBuffer(const Nav2SourceParams& params, std::int64_t created_ns, PurgeRule rule = PurgeRule::kJazzy);

  // bufferCloud: cloud_W (global frame) stamped stamp_ns, received at now_ns, from a sensor at origin_W.
  void buffer_cloud(const Eigen::Vector3d& origin_W, const Eigen::Matrix3Xf& cloud_W, std::int64_t stamp_ns,
                    std::int64_t now_ns);
  // getObservations: purges at now_ns, then appends the kept observations to `out`, last received first.
  void get_observations(std::int64_t now_ns, std::vector<std::shared_ptr<const Nav2Observation>>& out);
  // purgeStaleObservations at now_ns.
  void purge_stale(std::int64_t now_ns);
  // isCurrent at now_ns.
  bool is_current(std::int64_t now_ns) const;
  // resetLastUpdated (the layer's reset at now_ns): last updated now, the observations kept.
  void reset_last_updated(std::int64_t now_ns) { last_updated_ns_ = now_ns; }

  const std::deque<std::shared_ptr<const Nav2Observation>>& observations() const { return list_; }
  std::int64_t last_updated_ns() const { return last_updated_ns_; }
  const Nav2SourceParams& params() const { return params_; }

 private:
  Nav2SourceParams params_;
  std::int64_t keep_ns_, expected_update_rate_ns_, last_updated_ns_;
  PurgeRule rule_;
  std::deque<std::shared_ptr<const Nav2Observation>> list_;  // front: last received
};

}  // namespace stvl::layer::nav2

#pragma once
// STVL's measurement buffer (spatio_temporal_voxel_layer/src/measurement_buffer.cpp) on simulated time: the
// readings one observation source keeps, which of them a map update applies, and whether the source is
// current. What STVL does, and this follows:
//   - a new reading goes to the front; the source's last-updated time becomes the time it arrived;
//   - observation_persistence 0: only the front reading is kept; it is applied again at every update until a
//     newer one arrives (whatever its age);
//   - observation_persistence P > 0: readings older than P before the last-updated time are dropped. STVL
//     measures their age from the last reading, not from now (costmap_2d's ObservationBuffer uses now), so
//     while a camera is stopped nothing is dropped and the last P seconds are applied again at every update;
//   - expected_update_rate R (a period in seconds): current when now - last_updated <= R; 0 = always current.
//     The last-updated time starts at the buffer's creation (the start of the run).
#include <deque>
#include <memory>
#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "layer/observation.hpp"

namespace stvl::layer {

class SourceBuffer {
 public:
  // Empty, last updated at created_s; observation_persistence_s and expected_update_rate_s as above (seconds).
  SourceBuffer(double observation_persistence_s, double expected_update_rate_s, double created_s = 0.0)
      : persistence_s_(observation_persistence_s),
        expected_update_rate_s_(expected_update_rate_s),
        last_updated_s_(created_s) {}

  // A reading (not null) arrives at its time_s (its delivery; its header stamp may be earlier: camera timing).
  void receive(std::shared_ptr<const Observation> reading);
  // What an update applies: newest first.
  const std::deque<std::shared_ptr<const Observation>>& readings() const { return readings_; }
  bool current(double now_s) const;  // source_current() at now_s with this buffer's times
  // ResetLastUpdatedTime (the layer's reset at now_s): last updated now, the readings kept.
  void reset_last_updated(double now_s) { last_updated_s_ = now_s; }
  // The newest reading's time (created_s before any), and the expected update period (seconds; 0: always current).
  double last_updated_s() const { return last_updated_s_; }
  double expected_update_rate_s() const { return expected_update_rate_s_; }

 private:
  double persistence_s_, expected_update_rate_s_, last_updated_s_;
  std::deque<std::shared_ptr<const Observation>> readings_;
};

// STVL's check: current when now_s - last_updated_s <= expected_update_rate_s, or the rate is 0.
bool source_current(double now_s, double last_updated_s, double expected_update_rate_s);

// The time a source is not current between two readings at last_s and next_s: (last_s + rate, next_s), when it
// is not empty; none with a rate of 0.
struct StaleSpan {
  double from_s = 0, to_s = 0;
};
// That span, or nullopt when it is empty or the rate is 0.
std::optional<StaleSpan> stale_span(double last_s, double next_s, double expected_update_rate_s);

}  // namespace stvl::layer

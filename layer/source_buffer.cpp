#include "layer/source_buffer.hpp"

namespace stvl::layer {

void SourceBuffer::receive(std::shared_ptr<const Observation> reading) {
  last_updated_s_ = reading->time_s;
  readings_.push_front(std::move(reading));
  if (persistence_s_ <= 0.0) {
    readings_.resize(1);
    return;
  }
  // RemoveStaleObservations (measurement_buffer.cpp): from the newest, the first reading whose header stamp is more
  // than observation_persistence before the last reception (STVL's _last_updated) goes with every one after it. With
  // stamps at reception that keeps the newest; a reading stamped earlier than it arrived can go at once.
  for (auto it = readings_.begin(); it != readings_.end(); ++it)
    if (last_updated_s_ - (*it)->header_stamp_s() > persistence_s_) {
      readings_.erase(it, readings_.end());
      return;
    }
}

bool source_current(double now_s, double last_updated_s, double expected_update_rate_s) {
  return expected_update_rate_s <= 0.0 || now_s - last_updated_s <= expected_update_rate_s;
}

bool SourceBuffer::current(double now_s) const {
  return source_current(now_s, last_updated_s_, expected_update_rate_s_);
}

std::optional<StaleSpan> stale_span(double last_s, double next_s, double expected_update_rate_s) {
  if (expected_update_rate_s <= 0.0 || next_s - last_s <= expected_update_rate_s) return std::nullopt;
  return StaleSpan{last_s + expected_update_rate_s, next_s};
}

}  // namespace stvl::layer

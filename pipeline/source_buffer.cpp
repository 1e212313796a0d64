#include "pipeline/source_buffer.hpp"

#include <stdexcept>
#include <string>

#include "filter/passthrough.hpp"

namespace stvl::pipeline {

void SourceBuffer::receive(std::shared_ptr<const SourceReading> reading) {
  last_updated_s_ = reading->time_s;
  readings_.push_front(std::move(reading));
  if (persistence_s_ <= 0.0) {
    readings_.resize(1);
    return;
  }
  // Ages from the last reading (STVL's _last_updated), newest first: drop from the first one too old.
  while (readings_.size() > 1 && last_updated_s_ - readings_.back()->time_s > persistence_s_) readings_.pop_back();
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

Eigen::Matrix3Xf source_marking_W(const SourceReading& reading, const mapping::ObservationSource& source) {
  if (!source.marking) return Eigen::Matrix3Xf(3, 0);
  if (!source.height_band) return reading.marking_W;
  const double min_m = source.min_obstacle_height_m, max_m = source.max_obstacle_height_m;
  if (source.z_reference == mapping::ZReference::kGlobal) return filter::passthrough(reading.marking_W, {min_m, max_m});
  if (reading.marking_B.cols() != reading.marking_W.cols())
    throw std::logic_error("source_marking_W: a band in base_link needs the reading's marking_B (" +
                           std::to_string(reading.marking_B.cols()) + " points for " +
                           std::to_string(reading.marking_W.cols()) + ")");
  // PCL's PassThrough on the z of the cloud in base_link (inclusive, double limits); the points it keeps go on
  // as they were taken to the global frame.
  Eigen::Matrix3Xf out(3, reading.marking_W.cols());
  Eigen::Index n = 0;
  for (Eigen::Index i = 0; i < reading.marking_W.cols(); ++i) {
    const double z_B = reading.marking_B(2, i);
    if (!reading.marking_B.col(i).allFinite() || !reading.marking_W.col(i).allFinite() || z_B < min_m || z_B > max_m)
      continue;
    out.col(n++) = reading.marking_W.col(i);
  }
  out.conservativeResize(3, n);
  return out;
}

}  // namespace stvl::pipeline

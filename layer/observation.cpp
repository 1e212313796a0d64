#include "layer/observation.hpp"

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <string>

#include "filter/passthrough.hpp"

namespace stvl::layer {

Eigen::Matrix3Xf source_marking_W(const Observation& reading, const mapping::ObservationSource& source) {
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

HeightBand marking_band(const std::vector<SensorConfig>& sensors) {
  std::optional<HeightBand> band;
  for (const auto& sensor : sensors)
    for (const auto& source : sensor.sources) {
      if (!source.params.marking) continue;
      if (!band) band = HeightBand{source.params.min_obstacle_height_m, source.params.max_obstacle_height_m};
      band->min_m = std::min(band->min_m, source.params.min_obstacle_height_m);
      band->max_m = std::max(band->max_m, source.params.max_obstacle_height_m);
    }
  if (band) return *band;
  if (sensors.empty() || sensors.front().sources.empty()) return {};
  const auto& first = sensors.front().sources.front().params;
  return {first.min_obstacle_height_m, first.max_obstacle_height_m};
}

}  // namespace stvl::layer

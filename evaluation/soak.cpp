#include "evaluation/soak.hpp"

#include <unistd.h>

#include <fstream>

#include "common/units.hpp"

namespace stvl::evaluation {

double resident_memory_mb() {
  std::ifstream statm("/proc/self/statm");
  long size_pages = 0, resident_pages = 0;
  if (!(statm >> size_pages >> resident_pages)) return 0.0;
  return static_cast<double>(resident_pages) * static_cast<double>(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

SoakSampler::SoakSampler(double sample_every_s) : next_sample_s_(sample_every_s) {
  series_.sample_every_s = sample_every_s;
}

void SoakSampler::frame(double time_s, double map_ms, double map_cpu_ms, int laps, const mapping::VoxelMap& map) {
  if (!(series_.sample_every_s > 0)) return;
  interval_ms_ += map_ms;
  interval_cpu_ms_ += map_cpu_ms;
  ++interval_frames_;
  if (!series_.first_lap_end_s) {
    first_lap_ms_ += map_ms;
    first_lap_cpu_ms_ += map_cpu_ms;
    ++first_lap_frames_;
    if (laps >= 1) {
      series_.first_lap_end_s = time_s;
      series_.first_lap_map_ms = first_lap_ms_ / static_cast<double>(first_lap_frames_);
      series_.first_lap_map_cpu_ms = first_lap_cpu_ms_ / static_cast<double>(first_lap_frames_);
    }
  }
  series_.laps = laps;
  if (time_s + kTimeEpsilon_s < next_sample_s_) return;
  const double frames = static_cast<double>(interval_frames_);
  series_.samples.push_back(
      {time_s, map.size(), map.leaf_count(), resident_memory_mb(), interval_ms_ / frames, interval_cpu_ms_ / frames});
  interval_ms_ = 0.0;
  interval_cpu_ms_ = 0.0;
  interval_frames_ = 0;
  while (next_sample_s_ <= time_s + kTimeEpsilon_s) next_sample_s_ += series_.sample_every_s;
}

}  // namespace stvl::evaluation

#pragma once
// A long run's resources (issue #270, memory that grows over a long shift): every sample_every_s of simulated
// time the map's voxel and leaf counts, the process's resident memory and the mean per-frame map cost (clear + mark)
// since the previous sample. Resident memory and times measure the machine, not the run: metrics.json keeps them under
// timing_ms, out of the determinism check.
#include <cstddef>
#include <optional>
#include <vector>

#include "mapping/voxel_map.hpp"

namespace stvl::evaluation {

struct SoakSample {
  double t_s = 0.0;
  std::size_t voxels = 0;
  std::size_t leaves = 0;   // the map's 8^3 leaf nodes (its memory, but for the tree above them)
  double rss_mb = 0.0;      // resident memory, MiB
  double map_ms = 0.0;      // mean clear + mark ms per frame since the previous sample
  double map_cpu_ms = 0.0;  // the same in CPU time (layer::UpdateReport::cpu_ms)
};

struct SoakSeries {
  double sample_every_s = 0.0;  // 0: off
  int laps = 0;                 // laps of a looping path completed
  std::optional<double> first_lap_end_s;
  double first_lap_map_ms = 0.0;  // mean clear + mark ms per frame up to the end of the first lap
  double first_lap_map_cpu_ms = 0.0;
  std::vector<SoakSample> samples;
};

// The process's resident memory in MiB (/proc/self/statm); 0 where it cannot be read.
double resident_memory_mb();

class SoakSampler {
 public:
  // sample_every_s: simulated seconds between samples; 0 or less: off (frame() records nothing).
  explicit SoakSampler(double sample_every_s);
  // After each frame: its time, clear + mark ms (wall, CPU), the laps completed so far and the map (counted when
  // a sample is due).
  void frame(double time_s, double map_ms, double map_cpu_ms, int laps, const mapping::VoxelMap& map);
  const SoakSeries& series() const { return series_; }  // the samples and first-lap figures so far

 private:
  SoakSeries series_;
  double next_sample_s_ = 0.0;
  double interval_ms_ = 0.0, first_lap_ms_ = 0.0, interval_cpu_ms_ = 0.0, first_lap_cpu_ms_ = 0.0;
  std::size_t interval_frames_ = 0, first_lap_frames_ = 0;
};

}  // namespace stvl::evaluation

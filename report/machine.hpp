#pragma once
// The machine a run's timings were measured on (metrics.json "machine"): `stvl-bench compare` judges timing
// rules only between runs with the same fingerprint (issue 31: timings drift by tens of percent across hosts).
#include <nlohmann/json.hpp>

namespace stvl::report {

// {"cpu": model name, "logical_cpus", "memory_gib", "host", "fingerprint": 16 hex digits of FNV-1a over the four}.
// Read from /proc/cpuinfo, /proc/meminfo and gethostname(); what cannot be read is "" or 0.
nlohmann::json machine_json();

}  // namespace stvl::report

// Scenario YAML loader: any text either loads into a scenario whose parts validate, or throws
// std::invalid_argument (what `stvl-bench run` turns into exit 2). Any other exception, crash or sanitizer
// report is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "config/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  stvl::config::Scenario s;
  try {
    s = stvl::config::parse_scenario(text, "fuzz.yaml", "/nonexistent/scenarios");
  } catch (const std::invalid_argument& e) {
    if (std::string(e.what()).find("fuzz.yaml") == std::string::npos) {
      std::fprintf(stderr, "error message does not name the file: %s\n", e.what());
      std::abort();
    }
    return 0;
  }
  // Loaded: everything the runner relies on must already hold.
  s.camera().intrinsics.validate();
  s.pipeline.map.validate();
  s.camera().sources.front().params.validate();
  s.camera().noise.validate();
  if (!(s.duration_s > 0 && s.duration_s <= 3600) || s.pipeline.path.waypoints_W.empty() ||
      s.pipeline.world_path.empty())
    std::abort();
  return 0;
}

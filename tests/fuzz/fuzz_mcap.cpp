// rosbag2 MCAP (recording/mcap_*.cpp, ros2_source.cpp): any bytes, written to a .mcap file, either read as
// records and a recording or throw std::invalid_argument naming the file (exit 2 in `stvl-bench replay`). Any other
// exception, crash or sanitizer report is a finding. Seeds: small exports (zstd, lz4, none) and files written by
// @mcap/core (tests/recording/check_ros2_interop.sh makes both kinds).
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>

#include "recording/mcap.hpp"
#include "recording/recording.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  char path[] = "/tmp/stvl-fuzz-mcap-XXXXXX.mcap";
  const int fd = mkstemps(path, 5);
  if (fd < 0) std::abort();
  close(fd);
  {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  auto named = [&](const std::invalid_argument& e) {
    if (std::string(e.what()).find(path) == std::string::npos) {
      std::fprintf(stderr, "error message does not name the file: %s\n", e.what());
      std::abort();
    }
  };
  try {  // the records alone
    stvl::recording::detail::McapReader reader(path);
    stvl::recording::detail::McapRecord record;
    for (int i = 0; i < 100000 && reader.next(record); ++i) {
    }
  } catch (const std::invalid_argument& e) {
    named(e);
  }
  try {  // as a recording
    const auto recording = stvl::recording::open_recording(path);
    stvl::recording::RecordedFrame frame;
    for (int i = 0; i < 64 && recording->next(frame); ++i)
      for (float d : frame.depth.depth_m)
        if (!(d >= 0.0f) || !std::isfinite(d)) std::abort();
  } catch (const std::invalid_argument& e) {
    named(e);
  }
  std::remove(path);
  return 0;
}

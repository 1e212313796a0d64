// Recorded depth (recording/): any bytes, written to a file and opened as a recording, either read frame by frame
// or throw std::invalid_argument naming the file (what `stvl-bench replay` turns into exit 2). Any other
// exception, crash or sanitizer report is a finding. Seeds: small ROS 1 bags (uncompressed, bz2, lz4) written
// by tests/faults/make_bad_recording.py.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>

#include "recording/recording.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  char path[] = "/tmp/stvl-fuzz-recording-XXXXXX";
  const int fd = mkstemp(path);
  if (fd < 0) std::abort();
  close(fd);
  {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    const auto recording = stvl::recording::open_recording(path);
    stvl::recording::RecordedFrame frame;
    for (int i = 0; i < 64 && recording->next(frame); ++i) {
      frame.intrinsics.validate();
      if (frame.depth.width != frame.intrinsics.width || frame.depth.height != frame.intrinsics.height) std::abort();
      for (float d : frame.depth.depth_m)
        if (!(d >= 0.0f) || !std::isfinite(d)) std::abort();
    }
  } catch (const std::invalid_argument& e) {
    if (std::string(e.what()).find(path) == std::string::npos) {
      std::fprintf(stderr, "error message does not name the file: %s\n", e.what());
      std::abort();
    }
  }
  std::remove(path);
  return 0;
}

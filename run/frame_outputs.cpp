#include "run/frame_outputs.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "common/units.hpp"
#include "recording/bag_writer.hpp"

namespace stvl::run {
namespace {

namespace fs = std::filesystem;

// Whether `inner` is `outer` or lies below it (both resolved).
bool is_within(const fs::path& inner, const fs::path& outer) {
  const fs::path relative = inner.lexically_relative(outer);
  return !relative.empty() && *relative.begin() != "..";
}

// An absolute path with symbolic links and "..", "." resolved as far as it exists, without a trailing separator.
fs::path resolved(const std::string& path) {
  fs::path p = fs::weakly_canonical(fs::absolute(path)).lexically_normal();
  return p.filename().empty() ? p.parent_path() : p;
}

}  // namespace

void check_bag_outside_outputs(const std::string& out_dir, const std::string& bag_path, const std::string& bag_format) {
  if (out_dir.empty() || bag_path.empty()) return;
  const bool ros2 = recording::parse_bag_format(bag_format, bag_path) == recording::BagFormat::kRos2;
  const std::string bag = ros2 ? recording::ros2_bag_folder(bag_path) : bag_path;
  const fs::path out = resolved(out_dir);
  for (const std::string& taken : {bag, bag + ".active"}) {
    const fs::path bag_resolved = resolved(taken);
    if (!is_within(out, bag_resolved)) continue;
    throw std::invalid_argument("--bag " + bag_path + " writes " + (ros2 ? "the rosbag2 folder " : "the bag ") + taken +
                                ", which " + (out == bag_resolved ? "is" : "holds") + " the output folder --out " +
                                out_dir +
                                ": the outputs would replace the bag; write the bag beside --out or inside it");
  }
}

void StageSeries::append(const pipeline::SensingTimes& t, const layer::UpdateReport& update) {
  render.push_back(t.render_ms);
  noise.push_back(t.noise_ms);
  cloud.push_back(t.cloud_ms);
  filter.push_back(t.filter_ms);
  clear.push_back(update.clear_ms);
  mark.push_back(update.mark_ms);
}

Progress::Progress(bool enabled, double duration_s)
    : enabled_(enabled), tty_(isatty(fileno(stdout))), duration_s_(duration_s) {}

void Progress::update(double t_s, std::size_t frame) {
  if (!enabled_) return;
  const int percent = static_cast<int>(100.0 * std::min(1.0, t_s / duration_s_));
  if (tty_) {
    const int filled = percent / 4;
    std::printf("\r[%-25s] %3d%%  t=%6.2f s  frame %zu", std::string(filled, '#').c_str(), percent, t_s, frame);
    std::fflush(stdout);
  } else if (percent >= next_percent_) {
    std::printf("progress: %3d%%  t=%.2f s  frame %zu\n", percent, t_s, frame);
    next_percent_ = percent - percent % 10 + 10;
  }
}

void Progress::done() {
  if (enabled_ && tty_) std::printf("\n");
}

void write_sample_depth_frame(const std::filesystem::path& frames_dir, const std::string& prefix,
                              std::size_t frame_index, const sensors::DepthImage& depth, double min_range_m) {
  char name[64];
  std::snprintf(name, sizeof name, "depth_%05zu", frame_index);
  const std::string base = prefix + name;
  sensors::write_depth_png_mm(depth, (frames_dir / (base + ".png")).string());
  sensors::write_depth_png_colorized(depth, (frames_dir / (base + "_color.png")).string(), min_range_m, 6.0);
}

FrameSampler::FrameSampler(const std::filesystem::path& frames_dir, int count, double duration_s, double rate_hz,
                           std::string prefix)
    : dir_(frames_dir), prefix_(std::move(prefix)) {
  const std::size_t expected = static_cast<std::size_t>(duration_s / (1.0 / rate_hz)) + 1;
  every_ = count > 0 && !frames_dir.empty() ? std::max<std::size_t>(1, expected / (count + 1)) : 0;
}

void FrameSampler::offer(const pipeline::Frame& f, double min_range_m) const {
  if (!every_ || f.frame_index == 0 || f.frame_index % every_ != 0) return;
  write_sample_depth_frame(dir_, prefix_, f.frame_index, f.depth, min_range_m);
}

bool MapPublishClock::due(double time_s) {
  if (time_s + kTimeEpsilon_s < next_s_) return false;
  next_s_ = grid_ == Grid::kFixed ? next_s_ + period_s_ : time_s + period_s_;
  last_s_ = time_s;
  return true;
}

}  // namespace stvl::run

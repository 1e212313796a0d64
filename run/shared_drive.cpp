#include "run/shared_drive.hpp"

#include <regex>
#include <stdexcept>

#include "common/units.hpp"

namespace stvl::run {
namespace {

// Everything capture() and add_noise() give a frame; the rest (the edge filter's image, the clouds, the
// observations) is what each twin's sensing makes, in its own buffers.
void copy_capture(const pipeline::Frame& from, pipeline::Frame& to) {
  to.camera_index = from.camera_index;
  to.camera = from.camera;
  to.frame_index = from.frame_index;
  to.time_s = from.time_s;
  to.stamp_s = from.stamp_s;
  to.tf_from_messages = from.tf_from_messages;
  to.odom_messages = from.odom_messages;
  to.robot_upright = from.robot_upright;
  to.world = from.world;
  to.path_finished = from.path_finished;
  to.laps_completed = from.laps_completed;
  to.skipped_frames = from.skipped_frames;
  to.T_world_base = from.T_world_base;
  to.T_odom_base = from.T_odom_base;
  to.T_map_odom = from.T_map_odom;
  to.T_world_camera = from.T_world_camera;
  to.odom_v_mps = from.odom_v_mps;
  to.odom_omega_radps = from.odom_omega_radps;
  to.clean_depth = from.clean_depth;
  to.depth = from.depth;
  to.cameras_now = from.cameras_now;
  to.times = from.times;  // render and noise; the twin's sensing sets the rest
}

}  // namespace

std::string twin_sets_problem(const std::vector<std::string>& sets) {
  // What a twin may set: the layer, the filter, the evaluation and its checks, the outputs, the name, and each
  // camera's edge filter (it runs on the noisy image, in the sensing). Anything else may change what is simulated,
  // rendered or made noisy.
  static const std::regex own(
      R"((name|(map|filter|evaluation|checks|outputs|camera\.edge_filter|cameras\[[0-9]+\]\.edge_filter)([.\[].*)?))");
  for (const std::string& set : sets) {
    const std::size_t equals = set.find('=');
    if (equals == std::string::npos || equals == 0) return "'" + set + "' is not KEY=VALUE";
    const std::string key = set.substr(0, equals);
    if (!std::regex_match(key, own))
      return "'" + key +
             "' may change the drive (what is simulated, rendered or made noisy); a twin may set only map.*, "
             "filter.*, evaluation.*, checks.*, outputs.*, name and a camera's edge_filter.*";
  }
  return {};
}

TwinSpec parse_twin(const std::string& text) {
  TwinSpec twin;
  std::size_t begin = 0;
  for (;;) {
    const std::size_t end = text.find(';', begin);
    const std::string part = text.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
    if (begin == 0) twin.out_dir = part;
    else if (!part.empty()) twin.sets.push_back(part);
    if (end == std::string::npos) break;
    begin = end + 1;
  }
  if (twin.out_dir.empty()) throw std::invalid_argument("--twin '" + text + "': expected OUT;KEY=VALUE;...");
  if (const std::string problem = twin_sets_problem(twin.sets); !problem.empty())
    throw std::invalid_argument("--twin '" + text + "': " + problem);
  return twin;
}

SharedDrive::SharedDrive(pipeline::Pipeline& pipeline, std::size_t twins, double duration_s)
    : pipeline_(pipeline), duration_s_(duration_s), taken_(twins, 0), left_(twins, false) {
  pipeline_.set_world_snapshots(true);
  pipeline_.release_gl_contexts();  // the drive's thread draws from now on
  thread_ = std::thread([this] { drive(); });
}

SharedDrive::~SharedDrive() {
  stop();
  thread_.join();
}

bool SharedDrive::all_took() const {
  for (std::size_t t = 0; t < taken_.size(); ++t)
    if (!left_[t] && taken_[t] < captured_) return false;
  return true;
}

void SharedDrive::drive() {
  try {
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [this] { return stop_ || all_took(); });
        if (stop_ || ended_) break;
        if (pipeline_.next_time_s() > duration_s_ + kTimeEpsilon_s) {
          ended_ = true;
          break;
        }
      }
      // Frame k + 1 into the pipeline's next slot while the twins sense and evaluate frame k (its world, a snapshot,
      // is in another slot: the pipeline keeps kFramesInTurn >= 2).
      pipeline::Frame& f = pipeline_.capture();
      pipeline_.add_noise(f);
      std::lock_guard<std::mutex> lock(mutex_);
      if (stop_) break;
      latest_ = &f;
      ++captured_;
      ended_ = !f.robot_upright;  // the simulator stops at a fallen robot's frame
      changed_.notify_all();
    }
  } catch (...) {
    std::lock_guard<std::mutex> lock(mutex_);
    error_ = std::current_exception();
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ended_ = true;
  }
  changed_.notify_all();
  try {
    pipeline_.release_gl_contexts();  // so that the renderers can be freed on another thread
  } catch (...) {
  }
}

bool SharedDrive::take(std::size_t twin, pipeline::Frame& into) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [&] { return captured_ > taken_.at(twin) || ended_; });
  if (captured_ > taken_[twin]) {
    // The drive waits for this twin before the next capture: the frame stays as it is while it is copied.
    const pipeline::Frame* f = latest_;
    lock.unlock();
    copy_capture(*f, into);
    lock.lock();
    ++taken_[twin];
    lock.unlock();
    changed_.notify_all();
    return true;
  }
  if (error_) std::rethrow_exception(error_);
  return false;
}

void SharedDrive::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = ended_ = true;
  }
  changed_.notify_all();
}

void SharedDrive::leave(std::size_t twin) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    left_.at(twin) = true;
  }
  changed_.notify_all();
}

}  // namespace stvl::run

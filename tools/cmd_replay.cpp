// stvl-bench replay RECORDING [--out DIR] [--scenario FILE | --params ROS.yaml] ...: recorded depth through the
// same filter and map as a run (run/replay.hpp).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include "config/ros_binding.hpp"
#include "config/ros_nav2_layer.hpp"
#include "config/ros_params.hpp"
#include "config/scenario.hpp"
#include "report/report.hpp"
#include "run/replay.hpp"
#include "sim/diff_drive.hpp"
#include "tools/command.hpp"

namespace stvl::tools {
using namespace stvl::config;
using namespace stvl::run;
using namespace stvl::report;
namespace {

struct ReplayCommandOptions {
  std::string recording, out_dir, scenario, params, layer, costmap, bag, bag_compression, bag_format, bag_topics;
  std::vector<std::string> sets;
  ScenarioOverrides overrides;
  std::string depth_topic, info_topic, odom_topic, fixed_frame, camera_pose, camera_name;
  double rate_hz = 30.0;
  std::size_t max_frames = 0;
  bool no_progress = false, list_topics = false;
};

// "x,y,z,roll,pitch,yaw" (metres, radians): camera_link (x forward, z up) in the fixed frame.
Eigen::Isometry3d parse_pose(const std::string& text) {
  std::stringstream in(text);
  std::vector<double> v;
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw std::invalid_argument("--camera-pose: '" + item +
                                  "' is not a number (expected x,y,z,roll,pitch,yaw in m and rad)");
    }
  }
  if (v.size() != 6)
    throw std::invalid_argument("--camera-pose: expected 6 numbers x,y,z,roll,pitch,yaw, got " +
                                std::to_string(v.size()));
  for (double x : v)
    if (!std::isfinite(x)) throw std::invalid_argument("--camera-pose: values must be finite");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  T.linear() = (Eigen::AngleAxisd(v[5], Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(v[4], Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(v[3], Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  return T;
}

// The first segment of an absolute topic with more than one ("/camera/depth/points" -> "camera"); "" otherwise.
std::string first_segment(const std::string& topic) {
  const std::size_t end = topic.size() > 1 && topic[0] == '/' ? topic.find('/', 1) : std::string::npos;
  return end == std::string::npos ? "" : topic.substr(1, end - 1);
}

// realsense-ros names topics after the camera (/camera/depth/image_rect_raw): its first segment; "camera" for
// librealsense's /device_N/... and anything else.
std::string camera_name_of(const recording::RecordingInfo& info) {
  const std::string name = first_segment(info.depth_topic);
  return name.empty() || name.rfind("device_", 0) == 0 ? "camera" : name;
}

// The replay's settings from the options and the scenario: topics, rate, range, the camera's pose, samples and the
// pipeline (the recording's camera is named once the recording is open).
ReplaySettings replay_settings(const ReplayCommandOptions& o, const Scenario& scenario) {
  ReplaySettings settings;
  auto& r = settings.recording;
  r.depth_topic = o.depth_topic, r.info_topic = o.info_topic, r.odom_topic = o.odom_topic,
  r.fixed_frame = o.fixed_frame;
  r.rate_hz = o.rate_hz;
  const auto& camera = scenario.camera();
  r.min_range_m = camera.intrinsics.min_range_m, r.max_range_m = camera.intrinsics.max_range_m;
  const Eigen::Isometry3d T_link_optical = sim::DiffDriveRobot::T_camera_link_optical();
  if (o.camera_pose.empty()) {
    r.T_base_camera =
        sim::T_base_camera_link(camera.mount) * T_link_optical;  // the scenario's mount, base at the origin
  } else {
    r.T_fixed_base = Eigen::Isometry3d::Identity();
    r.T_base_camera = parse_pose(o.camera_pose) * T_link_optical;
  }
  settings.max_frames = o.max_frames;
  settings.sample_depth_frames = scenario.outputs.sample_depth_frames;
  settings.publish_period_s = scenario.outputs.publish_period_s;
  settings.pipeline = scenario.pipeline;
  return settings;
}

// --params: the file's STVL layer (or nav2's VoxelLayer / ObstacleLayer) on the pipeline; when its sources name no
// camera the recording's, the error says which --camera-name would bind it.
void apply_ros_params(const ReplayCommandOptions& o, ReplaySettings& settings) {
  if (ros_layer_is_nav2(o.params, o.layer, o.costmap)) {  // nav2's VoxelLayer or ObstacleLayer
    const RosNav2Layer layer = load_ros_nav2_layer(o.params, o.layer, o.costmap);
    try {
      apply_ros_nav2_layer(layer, settings.pipeline);
    } catch (const std::invalid_argument& e) {
      const std::string camera = layer.sources.empty() ? "" : first_segment(layer.sources.front().topic);
      if (!o.camera_name.empty() || camera.empty()) throw;
      throw std::invalid_argument(e.what() + ("; to bind the recording's camera to it, add --camera-name " + camera));
    }
    return;
  }
  const RosStvlLayer layer = load_ros_stvl_layer(o.params, o.layer, o.costmap);
  try {
    apply_ros_layer(layer, settings.pipeline, true);
  } catch (const std::invalid_argument& e) {
    // The recording's camera is named after its depth topic; the file may name it otherwise.
    std::string hint;
    for (const auto& source : layer.sources)
      if (source.enabled && !first_segment(source.topic).empty()) {
        hint = "; to bind the recording's camera to it, add --camera-name " + first_segment(source.topic);
        break;
      }
    if (!o.camera_name.empty() || hint.empty()) throw;
    throw std::invalid_argument(e.what() + hint);
  }
}

// The outputs: --out (default out/replay-<recording name>), the bag; SIGINT and SIGTERM stop the replay from here on.
RunOptions replay_run_options(const ReplayCommandOptions& o) {
  RunOptions options;
  options.out_dir = o.out_dir.empty() ? "out/replay-" + std::filesystem::path(o.recording).stem().string() : o.out_dir;
  options.bag_path = o.bag;
  options.bag_compression = o.bag_compression;
  options.bag_format = o.bag_format;
  options.bag_topics = o.bag_topics;
  options.progress = !o.no_progress;
  options.stop_requested = catch_stop_signals();
  return options;
}

void print_replay_summary(const ReplayCommandOptions& o, const ReplayResult& result, const std::string& out_dir) {
  const auto& k = result.pipeline.cameras.front().intrinsics;
  std::printf("replay: %s (%s, %s, poses: %s): %zu frames %dx%d, %.2f s recorded, real-time factor %.2f\n",
              o.recording.c_str(), result.recording.format.c_str(), result.recording.encoding.c_str(),
              recording::to_string(result.recording.pose_source), result.frames, k.width, k.height, result.sim_time_s,
              result.real_time_factor);
  std::printf("replay: map %zu voxels at %.3f m, %zu lethal cells; no ground truth, so no checks; outputs in %s\n",
              result.final_voxels, result.pipeline.map.voxel_size_m, result.lethal_cells, out_dir.c_str());
}

// --list-topics: every topic of the recording with its type, count and encodings, and what a replay with these
// options reads it as, or why the replay would stop. Exit 0; 2 when the recording cannot be read at all.
int list_topics(const ReplayCommandOptions& o, const ReplaySettings& settings) {
  recording::RecordingContents contents;
  std::string outcome;
  try {
    const auto opened = recording::open_recording(o.recording, settings.recording);
    const auto& info = opened->info();
    contents = recording::RecordingContents{info.path, info.format, info.files, info.topics, {}};
    outcome = "replay reads " + std::to_string(info.frame_count) + " depth frames" +
              (info.depth_topic.empty() ? std::string() : " from " + info.depth_topic) +
              " (poses: " + recording::to_string(info.pose_source) + ")";
  } catch (const std::invalid_argument& e) {
    // Read again without choosing topics (throws, exit 2, when the recording cannot be read at all).
    contents = recording::list_recording(o.recording);
    outcome = std::string("replay would stop: ") + e.what();
  }
  // The recording's warnings (a file cut short, a schema of a topic not read that does not parse) were printed as
  // it was opened.
  const std::vector<recording::TopicSummary>& topics = contents.topics;
  std::printf("recording: %s: %s, %zu file(s), %zu topic(s)\n", o.recording.c_str(), contents.format.c_str(),
              contents.files.size(), topics.size());
  for (const auto& t : topics) {
    const std::string encodings =
        t.message_encoding + "/" + (t.schema_encoding.empty() ? std::string("no schema") : t.schema_encoding);
    const std::string use =
        t.use.empty() ? "not read" + (t.note.empty() ? std::string() : ": " + t.note) : "read as " + t.use;
    std::printf("  %s  %s  %llu message(s)  %s  %s\n", t.name.c_str(), t.type.empty() ? "(no type)" : t.type.c_str(),
                static_cast<unsigned long long>(t.messages), encodings.c_str(), use.c_str());
  }
  std::printf("%s\n", outcome.c_str());
  return kExitOk;
}

int replay(const ReplayCommandOptions& o) {
  Scenario scenario = load_scenario(o.scenario.empty() ? default_scenario_path() : o.scenario, o.sets);
  apply_overrides(scenario, o.overrides);
  ReplaySettings settings = replay_settings(o, scenario);
  if (o.list_topics) return list_topics(o, settings);
  const std::unique_ptr<recording::Recording> recording = recording::open_recording(o.recording, settings.recording);
  settings.camera_name = o.camera_name.empty() ? camera_name_of(recording->info()) : o.camera_name;
  settings.pipeline.cameras.resize(1);
  settings.pipeline.cameras.front().name = settings.camera_name;
  if (!o.params.empty()) apply_ros_params(o, settings);

  const RunOptions options = replay_run_options(o);
  const ReplayResult result = replay_recording(*recording, settings, options);
  if (result.interrupted) {
    std::fprintf(stderr, "stvl-bench: interrupted by signal %d after %zu frames; no result written\n", caught_signal(),
                 result.frames);
    return 128 + caught_signal();
  }
  write_replay_report(result, options.out_dir);
  print_replay_summary(o, result, options.out_dir);
  return kExitOk;
}

const CommandRegistration kReplay("replay", [](CLI::App& app) {
  auto o = std::make_shared<ReplayCommandOptions>();
  auto* cmd = app.add_subcommand("replay",
                                 "Replay recorded depth (a ROS 1 bag, a rosbag2 folder / .mcap / .db3, or a folder of "
                                 "16-bit PNGs) through the filter and map");
  cmd->add_option("recording", o->recording,
                  "A ROS 1 bag, a rosbag2 folder, .mcap or .db3, or a folder of 16-bit depth PNGs")
      ->required();
  cmd->add_option("--out", o->out_dir, "Output directory (default: out/replay-<recording name>)");
  cmd->add_option(
      "--scenario", o->scenario,
      "Scenario whose first camera's sources, filter and map settings to use (default: the default corridor's)");
  cmd->add_option("--set", o->sets, "Set a scenario key before it is read, KEY=VALUE (repeatable)")
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option(
      "--params", o->params,
      "A nav2 / move_base / bare ROS parameter file whose STVL layer (or nav2 VoxelLayer / ObstacleLayer) to use");
  cmd->add_option("--layer", o->layer, "The STVL layer's name in --params (default: the only one)");
  cmd->add_option("--costmap", o->costmap, "The costmap holding the layer in --params (default: the only one)");
  cmd->add_option("--voxel-size", o->overrides.voxel_size_m, "Override the map and filter voxel size (m)");
  cmd->add_option("--filter", o->overrides.filter_type, "Override the filter: none | passthrough | voxel | csnb");
  cmd->add_option("--device", o->overrides.device, "Override the filter device: cpu | cuda | auto");
  cmd->add_option("--depth-topic", o->depth_topic, "Bag: the depth image topic (default: found)");
  cmd->add_option("--info-topic", o->info_topic, "Bag: the camera_info topic (default: beside the depth topic)");
  cmd->add_option("--odom-topic", o->odom_topic, "Bag: take the base's poses from this nav_msgs/Odometry topic");
  cmd->add_option("--fixed-frame", o->fixed_frame, "Bag: the tf frame poses are given in (default: the tree's root)");
  cmd->add_option(
      "--camera-pose", o->camera_pose,
      "Without poses in the recording: camera_link (x forward, z up) in the fixed frame, x,y,z,roll,pitch,yaw "
      "(m, rad; default: the scenario's camera mount on a base at the origin)");
  cmd->add_option("--camera-name", o->camera_name,
                  "The camera's name for --params' topics and the bag (default: from the depth topic)");
  cmd->add_option("--rate", o->rate_hz, "PNG folder without timestamps: frames per second")->check(CLI::PositiveNumber);
  cmd->add_option("--max-frames", o->max_frames, "Replay at most this many frames (0: all)");
  cmd->add_option("--bag", o->bag,
                  "Also write the replay as a ROS 1 bag or (FILE.mcap) a rosbag2 folder: depth, clouds, map, costmap");
  add_bag_options(*cmd, o->bag_format, o->bag_compression, o->bag_topics);
  cmd->add_flag("--no-progress", o->no_progress, "No progress output");
  cmd->add_flag("--list-topics", o->list_topics,
                "List the recording's topics (type, messages, encodings) and what the replay reads; replay nothing");
  return [o] { return replay(*o); };
});

}  // namespace
}  // namespace stvl::tools

#include "tools/runner.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "filter/filter.hpp"
#include "mapping/voxel_map.hpp"
#include "sensors/depth_noise.hpp"
#include "sensors/depth_renderer.hpp"
#include "sim/simulator.hpp"
#include "common/atomic_file.hpp"
#include "tools/bag_writer.hpp"
#include "tools/serial_worker.hpp"

namespace stvl::tools {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

class Progress {
 public:
  Progress(bool enabled, double duration_s) : enabled_(enabled), tty_(isatty(fileno(stdout))), duration_s_(duration_s) {}
  void update(double t_s, std::size_t frame) {
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
  void done() {
    if (enabled_ && tty_) std::printf("\n");
  }

 private:
  bool enabled_, tty_;
  double duration_s_;
  int next_percent_ = 0;
};

std::vector<std::uint16_t> to_millimetres(const sensors::DepthImage& image) {
  std::vector<std::uint16_t> mm(image.depth_m.size());
  for (std::size_t i = 0; i < mm.size(); ++i)
    mm[i] = static_cast<std::uint16_t>(std::min(65535.0, std::round(image.depth_m[i] * 1000.0)));
  return mm;
}

Eigen::Matrix3Xf transform(const Eigen::Isometry3d& T, const Eigen::Matrix3Xf& points, Eigen::Index count) {
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  return (R * points.leftCols(count)).colwise() + t;
}

std::vector<std::int8_t> occupancy(const mapping::Costmap2D& costmap) {
  std::vector<std::int8_t> data(costmap.cells.size());
  for (std::size_t i = 0; i < data.size(); ++i)
    data[i] = costmap.cells[i] == mapping::kCostLethal ? 100 : costmap.cells[i] == mapping::kCostUnknown ? -1 : 0;
  return data;
}

void add_check(RunResult& r, const std::string& name, bool passed, const std::string& message) {
  r.checks.push_back({name, passed, message});
}

std::string fmt(const char* format, double a, double b) {
  char text[160];
  std::snprintf(text, sizeof text, format, a, b);
  return text;
}

void run_checks(RunResult& r) {
  const auto& c = r.scenario.checks;
  const auto& mean = r.evaluation.mean;
  if (c.f1_3d_min) add_check(r, "f1_3d", mean.f1 >= *c.f1_3d_min, fmt("mean 3D F1 %.4f, required >= %.4f", mean.f1, *c.f1_3d_min));
  if (c.iou_3d_min) add_check(r, "iou_3d", mean.iou >= *c.iou_3d_min, fmt("mean 3D IoU %.4f, required >= %.4f", mean.iou, *c.iou_3d_min));
  if (c.costmap_precision_min)
    add_check(r, "costmap_precision", mean.costmap_precision >= *c.costmap_precision_min,
              fmt("mean costmap precision %.4f, required >= %.4f", mean.costmap_precision, *c.costmap_precision_min));
  if (c.costmap_recall_min)
    add_check(r, "costmap_recall", mean.costmap_recall >= *c.costmap_recall_min,
              fmt("mean costmap recall %.4f, required >= %.4f", mean.costmap_recall, *c.costmap_recall_min));
  if (c.all_obstacles_detected) {
    std::string missed;
    int observed = 0;
    for (const auto& o : r.evaluation.obstacles) {
      observed += o.observed;
      if (o.observed && !o.detected) missed += (missed.empty() ? "" : ", ") + o.name;
    }
    add_check(r, "all_obstacles_detected", missed.empty() && observed > 0,
              observed == 0 ? "no obstacle was observed" : missed.empty() ? std::to_string(observed) + " observed obstacles all detected" : "missed: " + missed);
  }
  if (c.phantom_obstacles_max)
    add_check(r, "phantom_obstacles", r.evaluation.final.phantom_obstacles <= *c.phantom_obstacles_max,
              fmt("%.0f phantom obstacles in the final costmap, allowed %.0f", r.evaluation.final.phantom_obstacles,
                  *c.phantom_obstacles_max));
  if (c.clearing_latency_max_s) {
    const auto& cl = r.evaluation.clearing;
    const bool ok = cl.stale_voxels_seen_through > 0 && cl.not_cleared == 0 && cl.max_latency_s <= *c.clearing_latency_max_s;
    add_check(r, "clearing_latency", ok,
              cl.stale_voxels_seen_through == 0 ? "no stale voxel of a moved body was seen through"
                                                : fmt("max latency %.3f s, required <= %.3f s", cl.max_latency_s, *c.clearing_latency_max_s) +
                                                      " (" + std::to_string(cl.not_cleared) + " never cleared)");
  }
  if (c.accuracy_p90_max_m)
    add_check(r, "accuracy_p90", r.evaluation.accuracy.p90_m <= *c.accuracy_p90_max_m,
              fmt("p90 distance to the true surface %.4f m, required <= %.4f m", r.evaluation.accuracy.p90_m, *c.accuracy_p90_max_m));
}

}  // namespace

bool RunResult::passed() const {
  for (const auto& c : checks)
    if (!c.passed) return false;
  return !interrupted;
}

RunResult run_scenario(const Scenario& s, const RunOptions& options) {
  RunResult r;
  r.scenario = s;
  const std::filesystem::path out = options.out_dir;
  const auto simulator = make_simulator(s);
  sim::Simulator& sim = *simulator;
  const auto& intrinsics = s.camera.intrinsics;
  sensors::DepthRenderer renderer(sim.world().model(), intrinsics, s.camera.gl_backend);
  sensors::DepthNoise noise(s.camera.noise, intrinsics);
  // The decimation runs on the whole cloud so that ray-cast clearing also sees the floor behind a moved
  // obstacle; the passthrough band then applies to the marking cloud only, as STVL applies it before marking.
  filter::FilterConfig decimation = s.filter;
  decimation.passthrough_enabled = false;
  if (decimation.type == filter::FilterType::kPassthrough) decimation.type = filter::FilterType::kNone;
  const bool passthrough = s.filter.passthrough_enabled || s.filter.type == filter::FilterType::kPassthrough;
  filter::Filter filter(decimation);
  mapping::VoxelMap map(s.map);
  Evaluator evaluator(sim.world(), s);
  if (!options.out_dir.empty()) ensure_writable_directory(out / "frames");
  r.gl_backend = renderer.backend_name();
  r.filter_device = filter.device_used();

  std::unique_ptr<BagWriter> bag;
  if (!options.bag_path.empty()) {
    bag = std::make_unique<BagWriter>(options.bag_path, parse_bag_compression(options.bag_compression));
    bag->write_tf_static(sim.robot().T_base_camera_link(), sim::DiffDriveRobot::T_camera_link_optical());
    bag->write_points("/ground_truth/occupancy", 0.0, kMapFrame, evaluator.truth_voxel_centers(), true);
  }
  // The bag is written on its own thread (declared after the bag, so it stops first); the frame loop only
  // copies what each message needs.
  std::unique_ptr<SerialWorker> bag_worker = bag ? std::make_unique<SerialWorker>() : nullptr;

  const double period_s = 1.0 / intrinsics.rate_hz;
  const std::size_t expected_frames = static_cast<std::size_t>(s.duration_s / period_s) + 1;
  const std::size_t sample_every =
      s.evaluation.sample_depth_frames > 0 ? std::max<std::size_t>(1, expected_frames / (s.evaluation.sample_depth_frames + 1)) : 0;
  double next_evaluation_s = s.evaluation.evaluate_every_s;
  double next_publish_s = 0.0;
  sensors::DepthImage noisy;
  Eigen::Matrix3Xf points_C;
  Progress progress(options.progress, s.duration_s);
  const auto wall_start = Clock::now();
  bool path_done_reported = false;

  for (std::size_t k = 0;; ++k) {
    const double t = k * period_s;
    if (t > s.duration_s + 1e-9) break;
    if (options.stop_requested && options.stop_requested->load()) {
      r.interrupted = true;
      break;
    }
    sim.run_until(t);
    const Eigen::Isometry3d T_world_base = sim.T_world_base();
    if (sim.robot().tilt_rad() > 0.5 || T_world_base.translation().z() < -0.5 || !T_world_base.translation().allFinite()) {
      add_check(r, "robot_upright", false,
                fmt("the robot fell over or left the world at t = %.2f s (tilt %.2f rad)", t, sim.robot().tilt_rad()));
      break;
    }
    const Eigen::Isometry3d T_world_camera = sim.T_world_camera();
    r.path_W.emplace_back(T_world_base.translation().head<2>());

    auto start = Clock::now();
    const sensors::DepthImage& clean = renderer.render(sim.world().model(), sim.world().data(), T_world_camera);
    r.times.render.push_back(ms_since(start));

    start = Clock::now();
    noisy = clean;
    noise.apply(noisy, s.seed, k);
    r.times.noise.push_back(ms_since(start));

    start = Clock::now();
    const Eigen::Index count = sensors::depth_to_cloud(noisy, intrinsics, points_C);
    const Eigen::Matrix3Xf points_W = transform(T_world_camera, points_C, count);
    r.times.cloud.push_back(ms_since(start));

    start = Clock::now();
    const Eigen::Matrix3Xf decimated_W = filter.apply(points_W);
    const Eigen::Matrix3Xf filtered_W = passthrough ? filter::passthrough(decimated_W, s.filter.passthrough) : decimated_W;
    r.times.filter.push_back(ms_since(start));

    start = Clock::now();
    evaluator.observe_clearing(t, sim.world(), clean, intrinsics, T_world_camera, map);
    double evaluation_ms = ms_since(start);

    // STVL's order: clear with the new observation, then mark it.
    start = Clock::now();
    mapping::ClearingObservation observation{T_world_camera, s.source, &decimated_W};
    map.clear({observation}, t);
    r.times.clear.push_back(ms_since(start));
    start = Clock::now();
    map.mark(filtered_W, T_world_camera, s.source, t);
    r.times.mark.push_back(ms_since(start));

    start = Clock::now();
    evaluator.after_update(t, map);
    evaluator.observe(t, clean, intrinsics, T_world_camera);
    if (t + 1e-9 >= next_evaluation_s) {
      evaluator.evaluate(t, sim.world(), map);
      next_evaluation_s += s.evaluation.evaluate_every_s;
    }
    r.times.evaluation.push_back(evaluation_ms + ms_since(start));

    if (sample_every && k % sample_every == 0 && k > 0 && !options.out_dir.empty()) {
      char name[64];
      std::snprintf(name, sizeof name, "depth_%05zu", k);
      sensors::write_depth_png_mm(noisy, (out / "frames" / (std::string(name) + ".png")).string());
      sensors::write_depth_png_colorized(noisy, (out / "frames" / (std::string(name) + "_color.png")).string(),
                                         intrinsics.min_range_m, 6.0);
    }

    start = Clock::now();
    if (bag) {
      const bool publish_map = t + 1e-9 >= next_publish_s;
      if (publish_map) next_publish_s += s.voxel_grid_publish_period_s;
      std::optional<mapping::Costmap2D> costmap;
      if (publish_map && !map.empty()) costmap = map.project_costmap();
      bag_worker->submit([&bag, t, T_world_base, T_map_odom = sim.T_map_odom(), T_odom_base = sim.T_odom_base(),
                          v = sim.odometry().v_mps(), omega = sim.odometry().omega_radps(), intrinsics,
                          depth_mm = to_millimetres(noisy), cloud_C = Eigen::Matrix3Xf(points_C.leftCols(count)),
                          filtered_W, voxels = publish_map ? map.voxel_centers() : Eigen::Matrix3Xf(), publish_map,
                          costmap = std::move(costmap)] {
        bag->write_clock(t);
        bag->write_tf(t, T_map_odom, T_odom_base);
        bag->write_odometry(t, T_odom_base, v, omega);
        bag->write_ground_truth_pose(t, T_world_base);
        bag->write_depth_image(t, intrinsics.width, intrinsics.height, depth_mm);
        bag->write_camera_info(t, intrinsics.width, intrinsics.height, intrinsics.fx, intrinsics.fy, intrinsics.cx,
                               intrinsics.cy);
        bag->write_points("/camera/depth/points", t, kCameraOpticalFrame, cloud_C);
        bag->write_points("/stvl/filtered_points", t, kMapFrame, filtered_W);
        if (publish_map) bag->write_points("/stvl/voxel_grid", t, kMapFrame, voxels);
        if (costmap)
          bag->write_occupancy_grid(t, costmap->resolution_m, costmap->origin_m.x(), costmap->origin_m.y(), costmap->width,
                                    costmap->height, occupancy(*costmap));
      });
    }
    r.times.bag.push_back(ms_since(start));

    r.points_raw.push_back(static_cast<std::size_t>(count));
    r.points_filtered.push_back(static_cast<std::size_t>(filtered_W.cols()));
    r.map_voxels.push_back(map.size());
    r.times.frame.push_back(r.times.render.back() + r.times.noise.back() + r.times.cloud.back() + r.times.filter.back() +
                            r.times.clear.back() + r.times.mark.back() + r.times.evaluation.back() + r.times.bag.back());
    r.frames = k + 1;
    r.sim_time_s = t;
    progress.update(t, k + 1);
    if (s.stop_at_path_end && sim.path_finished()) {
      path_done_reported = true;
      break;
    }
  }
  progress.done();
  r.wall_time_s = std::chrono::duration<double>(Clock::now() - wall_start).count();
  r.real_time_factor = r.wall_time_s > 0 ? r.sim_time_s / r.wall_time_s : 0;
  if (r.interrupted) return r;  // the bag stays as <bag>.active; no result file is written

  const bool fell = !r.checks.empty();
  if (!fell) add_check(r, "robot_upright", true, "the robot stayed upright on the floor");
  if (s.stop_at_path_end && !fell)
    add_check(r, "path_completed", path_done_reported,
              path_done_reported ? fmt("reached the end of the path at t = %.2f s%.0s", r.sim_time_s, 0)
                                 : fmt("did not reach the end of the path within %.1f s%.0s", s.duration_s, 0));
  if (r.frames > 0) {
    r.evaluation = evaluator.finish(r.sim_time_s, sim.world(), map);
    r.top_down = evaluator.top_down();
    run_checks(r);
  }
  if (bag) {
    bag_worker->finish();
    bag->close();
  }
  if (!options.out_dir.empty()) {
    map.save_vdb((out / "map.vdb").string());
    map.save_ply((out / "map.ply").string());  // deterministic bytes (a .vdb file carries a random UUID)
    if (!map.empty()) {
      mapping::CostmapOptions costmap_options;
      costmap_options.min_obstacle_height_m = s.source.min_obstacle_height_m;
      costmap_options.max_obstacle_height_m = s.source.max_obstacle_height_m;
      mapping::write_costmap(map.project_costmap(costmap_options), (out / "costmap").string());
    }
  }
  return r;
}

}  // namespace stvl::tools

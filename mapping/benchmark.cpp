#include "mapping/benchmark.hpp"

#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <memory>
#include <ostream>
#include <random>
#include <stdexcept>
#include <string>

#include "mapping/voxel_map.hpp"

#ifdef STVL_HAVE_OCTOMAP
#include <octomap/octomap.h>
#endif

namespace stvl::mapping {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kImageWidth = 424;
constexpr int kImageHeight = 240;
constexpr double kHorizontalFov = 87.0 * kPi / 180.0;
constexpr double kVerticalFov = 58.0 * kPi / 180.0;
constexpr double kMinRange = 0.2;
constexpr double kMaxRange = 5.0;
constexpr double kFrameRate = 30.0;
constexpr double kCorridorHalfWidth = 1.0;
constexpr double kCeiling = 2.6;

struct Box {
  Eigen::Vector3d lo, hi;
};
const Box kBoxes[] = {
    {{3.0, 0.4, 0.0}, {3.5, 1.0, 0.8}},
    {{5.0, -1.0, 0.0}, {5.6, -0.5, 1.2}},
    {{8.0, -0.2, 0.0}, {8.3, 0.2, 1.8}},
    {{11.0, 0.3, 0.0}, {11.8, 1.0, 0.5}},
};

double ray_box(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Box& b) {
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-12) {
      if (o[a] < b.lo[a] || o[a] > b.hi[a]) return std::numeric_limits<double>::infinity();
      continue;
    }
    double ta = (b.lo[a] - o[a]) / d[a], tb = (b.hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1 && t0 > 0.0 ? t0 : std::numeric_limits<double>::infinity();
}

double ray_scene(const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  double t = std::numeric_limits<double>::infinity();
  auto plane = [&](int axis, double value) {
    if (std::abs(d[axis]) < 1e-12) return;
    const double ti = (value - o[axis]) / d[axis];
    if (ti > 0.0) t = std::min(t, ti);
  };
  plane(1, kCorridorHalfWidth);
  plane(1, -kCorridorHalfWidth);
  plane(2, 0.0);
  plane(2, kCeiling);
  plane(0, 30.0);
  for (const Box& b : kBoxes) t = std::min(t, ray_box(o, d, b));
  return t;
}

Eigen::Matrix3Xf voxel_filter(const std::vector<Eigen::Vector3d>& points, double voxel_size) {
  std::vector<std::pair<Eigen::Vector3i, Eigen::Vector3d>> keyed;
  keyed.reserve(points.size());
  for (const auto& p : points) keyed.emplace_back((p / voxel_size).array().floor().cast<int>(), p);
  auto less = [](const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  };
  std::sort(keyed.begin(), keyed.end(), [&](const auto& a, const auto& b) { return less(a.first, b.first); });
  std::vector<Eigen::Vector3f> out;
  for (std::size_t i = 0; i < keyed.size();) {
    std::size_t j = i;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (; j < keyed.size() && keyed[j].first == keyed[i].first; ++j) sum += keyed[j].second;
    out.push_back((sum / static_cast<double>(j - i)).cast<float>());
    i = j;
  }
  Eigen::Matrix3Xf cloud(3, static_cast<Eigen::Index>(out.size()));
  for (std::size_t i = 0; i < out.size(); ++i) cloud.col(static_cast<Eigen::Index>(i)) = out[i];
  return cloud;
}

template <typename F>
double time_ms(F&& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

ObservationSource bench_source() {
  ObservationSource source;
  source.marking = true;
  source.clearing = true;
  source.obstacle_range_m = kMaxRange;
  source.min_obstacle_height_m = 0.05;
  source.max_obstacle_height_m = 2.0;
  source.horizontal_fov_rad = kHorizontalFov;
  source.vertical_fov_rad = kVerticalFov;
  source.min_z_m = kMinRange;
  source.max_z_m = kMaxRange;
  source.decay_acceleration_per_s3 = 1.0;
  return source;
}

// Voxels behind the camera's path (x in [-20, -15) m), 100 x 100 per layer, all marked at t = 0.
std::vector<Voxel> prefill(std::size_t count, double voxel_size) {
  std::vector<Voxel> voxels;
  voxels.reserve(count);
  const int x0 = static_cast<int>(std::floor(-20.0 / voxel_size));
  for (std::size_t i = 0; i < count; ++i) {
    const int ix = static_cast<int>(i % 100), iy = static_cast<int>((i / 100) % 100), iz = static_cast<int>(i / 10000);
    voxels.push_back({{x0 + ix, iy - 50, iz}, 0.0});
  }
  return voxels;
}

}  // namespace

void MapBenchOptions::validate() const {
  StvlConfig config;
  config.voxel_size_m = voxel_size_m;
  config.validate();
  if (frames < 1 || frames > 100000) throw std::invalid_argument("frames = " + std::to_string(frames) + " must lie in [1, 100000]");
  if (sizes.empty()) throw std::invalid_argument("sizes is empty");
  if (threads < 0 || threads > 1024)
    throw std::invalid_argument("threads = " + std::to_string(threads) + " must lie in [0, 1024]");
  for (std::size_t s : sizes)
    if (s > 10'000'000) throw std::invalid_argument("size = " + std::to_string(s) + " exceeds 10^7 voxels");
}

SyntheticFrame synthetic_corridor_frame(std::uint64_t seed, int frame, double voxel_size) {
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ULL + static_cast<std::uint64_t>(frame));
  std::uniform_real_distribution<double> jitter(-1.0, 1.0);
  std::normal_distribution<double> unit(0.0, 1.0);
  SyntheticFrame out;
  out.time_s = 1.0 + frame / kFrameRate;
  const double x = 0.03 * frame;
  const double yaw = 0.15 * std::sin(0.05 * frame) + 0.01 * jitter(rng);
  // optical axes in the base frame: z forward (+x), x right (-y), y down (-z)
  Eigen::Matrix3d R_base_optical;
  R_base_optical << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  out.T_world_camera = Eigen::Isometry3d::Identity();
  out.T_world_camera.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_base_optical;
  out.T_world_camera.translation() = Eigen::Vector3d(x, 0.05 * jitter(rng), 0.5);
  const double fx = (kImageWidth / 2.0) / std::tan(kHorizontalFov / 2);
  const double fy = (kImageHeight / 2.0) / std::tan(kVerticalFov / 2);
  const Eigen::Vector3d o = out.T_world_camera.translation();
  std::vector<Eigen::Vector3d> points;
  points.reserve(kImageWidth * kImageHeight);
  for (int v = 0; v < kImageHeight; ++v) {
    for (int u = 0; u < kImageWidth; ++u) {
      const Eigen::Vector3d ray_C((u + 0.5 - kImageWidth / 2.0) / fx, (v + 0.5 - kImageHeight / 2.0) / fy, 1.0);
      const Eigen::Vector3d d_W = out.T_world_camera.linear() * ray_C;
      const double t = ray_scene(o, d_W);  // t is the depth along the optical axis since ray_C.z = 1
      if (!(t >= kMinRange && t <= kMaxRange)) continue;
      const double depth = t + 0.001 * t * t * unit(rng);
      points.push_back(o + d_W * depth);
    }
  }
  out.points_W = voxel_filter(points, voxel_size);
  return out;
}

MapBenchResult run_map_bench(const MapBenchOptions& options) {
  options.validate();
  std::unique_ptr<tbb::global_control> limit;
  if (options.threads > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, options.threads);
  MapBenchResult result;
  result.options = options;
  std::vector<SyntheticFrame> frames;
  double total_points = 0.0;
  for (int f = 0; f < options.frames; ++f) {
    frames.push_back(synthetic_corridor_frame(options.seed, f, options.voxel_size_m));
    total_points += static_cast<double>(frames.back().points_W.cols());
  }
  result.points_per_frame = total_points / options.frames;
  const ObservationSource source = bench_source();

  for (std::size_t size : options.sizes) {
    MapBenchRow row;
    row.prefilled_voxels = size;
    const std::vector<Voxel> fill = prefill(size, options.voxel_size_m);
    StvlConfig config;
    config.voxel_size_m = options.voxel_size_m;
    VoxelMap ours(config);
    config.clearing_walk = ClearingWalk::kFullWalk;
    VoxelMap full(config);
    config.clearing_walk = ClearingWalk::kBounded;
    config.clearing_mode = ClearingMode::kRaycast;
    VoxelMap raycast(config);
    for (VoxelMap* map : {&ours, &full, &raycast}) map->set_voxels(fill);
    std::vector<double> mark, clear, full_clear, ray_clear, ray_mark, octomap_insert;
#ifdef STVL_HAVE_OCTOMAP
    result.have_octomap = options.octomap;
    octomap::OcTree octree(options.voxel_size_m);
#endif
    for (const SyntheticFrame& frame : frames) {
      const std::vector<ClearingObservation> obs = {{frame.T_world_camera, source, &frame.points_W}};
      clear.push_back(time_ms([&] { ours.clear(obs, frame.time_s); }));
      mark.push_back(time_ms([&] { ours.mark(frame.points_W, frame.T_world_camera, source, frame.time_s); }));
      full_clear.push_back(time_ms([&] { full.clear(obs, frame.time_s); }));
      full.mark(frame.points_W, frame.T_world_camera, source, frame.time_s);
      ray_clear.push_back(time_ms([&] { raycast.clear(obs, frame.time_s); }));
      ray_mark.push_back(time_ms([&] { raycast.mark(frame.points_W, frame.T_world_camera, source, frame.time_s); }));
#ifdef STVL_HAVE_OCTOMAP
      if (options.octomap) {
        octomap::Pointcloud cloud;
        cloud.reserve(static_cast<std::size_t>(frame.points_W.cols()));
        for (Eigen::Index i = 0; i < frame.points_W.cols(); ++i)
          cloud.push_back(frame.points_W(0, i), frame.points_W(1, i), frame.points_W(2, i));
        const Eigen::Vector3f o = frame.T_world_camera.translation().cast<float>();
        octomap_insert.push_back(time_ms([&] { octree.insertPointCloud(cloud, octomap::point3d(o.x(), o.y(), o.z()), kMaxRange); }));
      }
#endif
    }
    row.octomap_insert_ms = median(octomap_insert);
    row.mark_ms = median(mark);
    row.clear_ms = median(clear);
    row.full_walk_clear_ms = median(full_clear);
    row.raycast_clear_ms = median(ray_clear);
    row.raycast_mark_ms = median(ray_mark);
    row.final_voxels = ours.size();
    const auto a = ours.voxels(), b = full.voxels();
    row.full_walk_matches = a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](const Voxel& x, const Voxel& y) {
                              return x.key == y.key && x.time_s == y.time_s;
                            });
    result.rows.push_back(row);
  }

  return result;
}

void print_map_bench(const MapBenchResult& r, std::ostream& out) {
  const auto flags = out.flags();
  out << std::fixed << std::setprecision(3);
  out << "map-bench: voxel_size " << r.options.voxel_size_m << " m, " << r.options.frames << " frames, "
      << std::setprecision(0) << r.points_per_frame << " points/frame (424x240 D435-like, voxel-filtered), seed "
      << r.options.seed << ", "
      << (r.options.threads > 0 ? std::to_string(r.options.threads) : std::string("all")) << " threads\n"
      << "median ms per frame; ratios against the first size in the same run\n\n";
  out << std::setprecision(3);
  out << "| prefilled voxels | mark | clear (ours) | clear (full walk) | full/ours | ours vs first | full vs first "
         "| raycast clear | raycast clear+mark | mark+clear (ours) | same map |\n"
      << "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|:---:|\n";
  const MapBenchRow& first = r.rows.front();
  for (const MapBenchRow& row : r.rows) {
    out << "| " << row.prefilled_voxels << " | " << row.mark_ms << " | " << row.clear_ms << " | "
        << row.full_walk_clear_ms << " | " << std::setprecision(1) << row.full_walk_clear_ms / row.clear_ms << "x | "
        << std::setprecision(2) << row.clear_ms / first.clear_ms << "x | "
        << row.full_walk_clear_ms / first.full_walk_clear_ms << "x | " << std::setprecision(3) << row.raycast_clear_ms
        << " | " << row.raycast_clear_ms + row.raycast_mark_ms << " | " << row.mark_ms + row.clear_ms << " | "
        << (row.full_walk_matches ? "yes" : "NO") << " |\n";
  }
  if (r.have_octomap) {
    out << "\nRay-cast (clear + mark) vs OctoMap OcTree::insertPointCloud on the same clouds, origins, voxel size and "
           "max range (fresh OcTree, interleaved frame by frame):\n\n"
        << "| prefilled voxels | raycast clear+mark | octomap insertPointCloud | speed-up |\n|---:|---:|---:|---:|\n";
    for (const MapBenchRow& row : r.rows) {
      const double ours = row.raycast_clear_ms + row.raycast_mark_ms;
      out << "| " << row.prefilled_voxels << " | " << std::setprecision(3) << ours << " | " << row.octomap_insert_ms
          << " | " << std::setprecision(1) << row.octomap_insert_ms / ours << "x |\n";
    }
  } else {
    out << "\nOctoMap peer not run (liboctomap not found at build time or --no-octomap)\n";
  }
  out.flags(flags);
}

}  // namespace stvl::mapping

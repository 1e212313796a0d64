#include "bench/sensors_bench.hpp"

#include <mujoco/mujoco.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/stopwatch.hpp"
#include "common/units.hpp"
#include "sensors/depth_noise.hpp"
#include "sensors/depth_renderer.hpp"
#ifdef STVL_HAVE_SENSORS_REFERENCE
#include "sensors/reference/gl_depth_renderer.hpp"
#endif

namespace stvl::bench {

namespace {

// A 3 m wide, 2.6 m high corridor, 20 m long along +x, with boxes, cylinders and spheres along it.
const char* kCorridor = R"(
<mujoco model="bench_corridor">
  <worldbody>
    <geom name="floor" type="box" size="12 2 0.05" pos="8 0 -0.05"/>
    <geom name="ceiling" type="box" size="12 2 0.05" pos="8 0 2.65"/>
    <geom name="wall_left" type="box" size="12 0.05 1.3" pos="8 1.55 1.3"/>
    <geom name="wall_right" type="box" size="12 0.05 1.3" pos="8 -1.55 1.3"/>
    <geom name="end" type="box" size="0.05 1.5 1.3" pos="19 0 1.3"/>
    <geom type="box" size="0.3 0.3 0.4" pos="2 0.8 0.4"/>
    <geom type="cylinder" size="0.2 0.5" pos="3.5 -0.7 0.5"/>
    <geom type="sphere" size="0.25" pos="5 0.2 0.25"/>
    <geom type="box" size="0.5 0.2 0.9" pos="7 -1.0 0.9"/>
    <geom type="cylinder" size="0.05 1.3" pos="9 0.9 1.3"/>
    <geom type="box" size="0.4 0.4 0.4" pos="12 0 0.4" euler="0 0 30"/>
  </worldbody>
</mujoco>)";

struct Result {
  double render_fps = 0.0, full_fps = 0.0, valid_fraction = 0.0, points = 0.0, noise_ms = 0.0, cloud_ms = 0.0;
  double noise_one_pass_ms = 0.0;  // the noise model's plain one-pass reference on the same frames (its peer)
  // The renderer before its readback was optimized (reference::FloatDepthRenderer), interleaved frame by frame;
  // peer_ms < 0 when the reference library was not built (STVL_BUILD_TESTS off).
  double render_ms = 0.0, peer_ms = -1.0;
  long peer_differing_pixels = 0;
  // Three cameras of one instant (yaw 0 and +-110 deg): render() one after another vs render_concurrently().
  double three_apart_ms = 0.0, three_together_ms = 0.0;
};

// A walk down the corridor at 0.4 m height, swaying +-10 deg, turned by yaw_rad.
Eigen::Isometry3d bench_pose(int i, double yaw_rad = 0.0) {
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d optical_to_body;  // optical z forward = body x, x right = -y, y down = -z
  optical_to_body << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  T_world_camera.linear() =
      Eigen::AngleAxisd(0.17 * std::sin(0.05 * i) + yaw_rad, Eigen::Vector3d::UnitZ()) * optical_to_body;
  T_world_camera.translation() = Eigen::Vector3d(0.01 * i, 0.0, 0.4);
  return T_world_camera;
}

double ms_of(SteadyClock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

// The peer and the three-camera rows of `r`, on the same frames as the rest.
void measure_peers(const mjModel* model, mjData* data, stvl::sensors::GlBackend backend,
                   const stvl::sensors::CameraIntrinsics& intrinsics, int frames, Result& r) {
  using namespace stvl::sensors;
  using clock = SteadyClock;
  DepthRenderer renderer(model, intrinsics, backend);
#ifdef STVL_HAVE_SENSORS_REFERENCE
  reference::FloatDepthRenderer peer(model, intrinsics, backend);
  double fast_ms = 0.0, peer_ms = 0.0;
  for (int i = -10; i < frames; ++i) {  // 10 warm-up frames
    const auto t0 = clock::now();
    const DepthImage& before = peer.render(model, data, bench_pose(i));
    const auto t1 = clock::now();
    const DepthImage& now = renderer.render(model, data, bench_pose(i));
    const auto t2 = clock::now();
    if (i < 0) continue;
    peer_ms += ms_of(t1 - t0), fast_ms += ms_of(t2 - t1);
    for (std::size_t p = 0; p < now.depth_m.size(); ++p)
      r.peer_differing_pixels += std::memcmp(&now.depth_m[p], &before.depth_m[p], sizeof(float)) != 0;
  }
  r.render_ms = fast_ms / frames, r.peer_ms = peer_ms / frames;
#endif
  DepthRenderer left(model, intrinsics, backend), right(model, intrinsics, backend);
  const std::vector<DepthRenderer*> three{&renderer, &left, &right};
  const double yaw[3] = {0.0, 1.92, -1.92};
  double apart_ms = 0.0, together_ms = 0.0;
  for (int i = -10; i < frames; ++i) {
    const std::vector<Eigen::Isometry3d> poses{bench_pose(i, yaw[0]), bench_pose(i, yaw[1]), bench_pose(i, yaw[2])};
    const auto t0 = clock::now();
    for (int c = 0; c < 3; ++c) three[c]->render(model, data, poses[c]);
    const auto t1 = clock::now();
    render_concurrently(three, model, data, poses);
    const auto t2 = clock::now();
    if (i >= 0) apart_ms += ms_of(t1 - t0), together_ms += ms_of(t2 - t1);
  }
  r.three_apart_ms = apart_ms / frames, r.three_together_ms = together_ms / frames;
}

Result measure(const std::string& world_path, stvl::sensors::GlBackend backend,
               const stvl::sensors::CameraIntrinsics& intrinsics, int frames, std::string& name) {
  using namespace stvl::sensors;
  char error[1000] = "";
  mjModel* model = mj_loadXML(world_path.c_str(), nullptr, error, sizeof(error));
  if (!model) throw std::runtime_error(std::string("cannot load ") + world_path + ": " + error);
  mjData* data = mj_makeData(model);
  mj_forward(model, data);
  Result result;
  {
    DepthRenderer renderer(model, intrinsics, backend);
    name = renderer.backend_name();
    DepthNoise noise(DepthNoiseConfig{}, intrinsics);
    DepthImage noisy;
    Eigen::Matrix3Xf points_C;
    const auto pose = [](int i) { return bench_pose(i); };
    for (int i = 0; i < 10; ++i) renderer.render(model, data, pose(i));  // warm-up
    using clock = SteadyClock;
    auto t0 = clock::now();
    double valid = 0.0;
    for (int i = 0; i < frames; ++i) valid += renderer.render(model, data, pose(i)).valid_count();
    result.render_fps = frames / s_since(t0);
    result.valid_fraction = valid / frames / (double(intrinsics.width) * intrinsics.height);
    t0 = clock::now();
    double points = 0.0, noise_s = 0.0, cloud_s = 0.0, one_pass_s = 0.0;
    DepthImage reference;
    for (int i = 0; i < frames; ++i) {
      noisy = renderer.render(model, data, pose(i));
      reference = noisy;
      const auto t0_ref = clock::now();
      noise.apply(reference, 7, uint64_t(i), /*parallel=*/false);
      one_pass_s += s_since(t0_ref);
      const auto t1 = clock::now();
      noise.apply(noisy, 7, uint64_t(i));
      const auto t2 = clock::now();
      points += double(depth_to_cloud(noisy, intrinsics, points_C));
      noise_s += std::chrono::duration<double>(t2 - t1).count();
      cloud_s += s_since(t2);
    }
    result.full_fps = frames / (s_since(t0) - one_pass_s);
    result.noise_one_pass_ms = kMsPerSecond * one_pass_s / frames;
    result.noise_ms = kMsPerSecond * noise_s / frames;
    result.cloud_ms = kMsPerSecond * cloud_s / frames;
    result.points = points / frames;
  }
  measure_peers(model, data, backend, intrinsics, frames, result);
  mj_deleteData(data);
  mj_deleteModel(model);
  return result;
}

}  // namespace

void SensorsBenchOptions::validate() const {
  if (frames < 1 || frames > 1000)
    throw std::invalid_argument("frames = " + std::to_string(frames) + " must lie in [1, 1000]");
  if (backends.empty()) throw std::invalid_argument("no GL backend given");
  for (const std::string& b : backends) sensors::parse_gl_backend(b);  // throws naming a bad one
}

void run_sensors_bench(const SensorsBenchOptions& options) {
  using namespace stvl::sensors;
  options.validate();
  std::string world_path = options.world_path;
  bool temporary_world = false;
  if (world_path.empty()) {
    world_path = "/tmp/stvl_sensors_bench_" + std::to_string(getpid()) + ".xml";
    std::ofstream(world_path) << kCorridor;
    temporary_world = true;
  }
  std::printf("%-7s %-8s %11s %19s %9s %17s %9s %7s %8s\n", "backend", "size", "render fps", "render+noise+cloud",
              "noise ms", "noise 1-pass ms", "cloud ms", "valid", "points");
  for (const std::string& backend_arg : options.backends) {
    std::fflush(stdout);
    const pid_t child = fork();
    if (child < 0) throw std::runtime_error("sensors-bench: fork failed");
    if (child == 0) {
      int status = 0;
      for (const CameraIntrinsics& k : {CameraIntrinsics::d435_640x480(), CameraIntrinsics::d435_848x480()}) {
        try {
          std::string name;
          const Result r = measure(world_path, parse_gl_backend(backend_arg), k, options.frames, name);
          std::printf("%-7s %4dx%-3d %11.1f %19.1f %9.2f %17.2f %9.2f %6.1f%% %8.0f\n", name.c_str(), k.width, k.height,
                      r.render_fps, r.full_fps, r.noise_ms, r.noise_one_pass_ms, r.cloud_ms, 100.0 * r.valid_fraction,
                      r.points);
          if (r.peer_ms >= 0.0) {
            std::printf(
                "        render %.2f ms vs the old readback (colour writes, float depth) %.2f ms, ratio %.3f, "
                "pixels differing %ld\n",
                r.render_ms, r.peer_ms, r.render_ms / r.peer_ms, r.peer_differing_pixels);
          }
          std::printf("        3 cameras of one instant: one after another %.2f ms, concurrently %.2f ms, ratio %.3f\n",
                      r.three_apart_ms, r.three_together_ms, r.three_together_ms / r.three_apart_ms);
        } catch (const std::exception& e) {
          std::printf("%-7s %4dx%-3d unavailable: %s\n", backend_arg.c_str(), k.width, k.height, e.what());
          status = 2;
        }
        std::fflush(stdout);
      }
      _exit(status);
    }
    int status = 0;
    waitpid(child, &status, 0);
  }
  if (temporary_world) std::remove(world_path.c_str());
}

}  // namespace stvl::bench

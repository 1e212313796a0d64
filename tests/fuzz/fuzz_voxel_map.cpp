// Voxel map: a sequence of mark / clear / costmap / lookup calls with arbitrary configs, poses, points and
// times. Calls either succeed or throw std::invalid_argument, and the map stays usable afterwards.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>

#include "fuzz_values.hpp"
#include "mapping/voxel_map.hpp"

using stvl::fuzz::any_value;
namespace m = stvl::mapping;

namespace {

m::ObservationSource any_source(FuzzedDataProvider& in) {
  m::ObservationSource s;
  s.marking = in.ConsumeIntegralInRange<int>(0, 7) != 0;
  s.clearing = in.ConsumeBool();
  if (in.ConsumeBool()) return s;
  s.obstacle_range_m = any_value<double>(in, 0.0, 20.0);
  s.min_obstacle_height_m = any_value<double>(in, -1.0, 1.0);
  s.max_obstacle_height_m = any_value<double>(in, 0.0, 3.0);
  s.horizontal_fov_rad = any_value<double>(in, 0.01, 3.2);
  s.vertical_fov_rad = any_value<double>(in, 0.01, 3.2);
  s.min_z_m = any_value<double>(in, 0.0, 1.0);
  s.max_z_m = any_value<double>(in, 0.0, 12.0);
  s.decay_acceleration_per_s3 = any_value<double>(in, 0.0, 100.0);
  return s;
}

Eigen::Matrix3Xf any_points(FuzzedDataProvider& in) {
  const int n = in.ConsumeIntegralInRange<int>(0, 256);
  Eigen::Matrix3Xf p(3, n);
  for (int i = 0; i < n; ++i)
    for (int r = 0; r < 3; ++r)
      p(r, i) =
          in.ConsumeBool() ? any_value<float>(in, -5.0f, 5.0f) : in.ConsumeFloatingPointInRange<float>(-4.0f, 4.0f);
  return p;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  m::StvlConfig config;
  config.voxel_size_m = in.ConsumeBool() ? 0.05 : any_value<double>(in, 0.01, 1.0);
  config.voxel_decay_s = any_value<double>(in, 0.0, 30.0);
  config.decay_model = static_cast<m::DecayModel>(in.ConsumeIntegralInRange<int>(-1, 2));
  config.mark_threshold = in.ConsumeIntegralInRange<int>(-1, 4);
  config.clearing_mode = in.ConsumeBool() ? m::ClearingMode::kFrustum : m::ClearingMode::kRaycast;
  config.clearing_walk = in.ConsumeBool() ? m::ClearingWalk::kBounded : m::ClearingWalk::kFullWalk;
  config.expiry_leaves_per_update = in.ConsumeIntegralInRange<std::size_t>(0, 512);

  std::unique_ptr<m::VoxelMap> map;
  try {
    map = std::make_unique<m::VoxelMap>(config);
  } catch (const std::invalid_argument&) {
    return 0;
  }
  double time_s = 0.0;
  for (int step = 0; step < 16 && in.remaining_bytes() > 0; ++step) {
    try {
      switch (in.ConsumeIntegralInRange<int>(0, 5)) {
        case 0:
        case 1: {
          const auto points = any_points(in);
          const auto pose = stvl::fuzz::any_pose(in);
          const auto source = any_source(in);
          time_s = in.ConsumeBool() ? time_s + in.ConsumeFloatingPointInRange<double>(0.0, 5.0)
                                    : any_value<double>(in, 0, 100);
          const std::size_t marked = map->mark(points, pose, source, time_s);
          if (marked > std::size_t(points.cols())) std::abort();
          break;
        }
        case 2:
        case 3: {
          const auto points = any_points(in);
          std::vector<m::ClearingObservation> observations(in.ConsumeIntegralInRange<int>(0, 3));
          for (auto& o : observations) {
            o.T_world_camera = stvl::fuzz::any_pose(in);
            o.source = any_source(in);
            o.points_W = in.ConsumeIntegralInRange<int>(0, 7) ? &points : nullptr;
          }
          time_s = in.ConsumeBool() ? time_s + in.ConsumeFloatingPointInRange<double>(0.0, 20.0)
                                    : any_value<double>(in, 0, 100);
          const std::size_t before = map->size();
          const auto stats = map->clear(observations, time_s);
          if (map->size() > before || stats.voxels_removed > before) std::abort();
          break;
        }
        case 4: {
          m::CostmapOptions options;
          if (in.ConsumeBool()) options.resolution_m = any_value<double>(in, 0.01, 1.0);
          const auto costmap = map->project_costmap(options);
          if (costmap.width < 1 || costmap.height < 1 || double(costmap.width) * costmap.height > 1e8) std::abort();
          break;
        }
        default: {
          const Eigen::Vector3d p(any_value<double>(in, -5, 5), any_value<double>(in, -5, 5),
                                  any_value<double>(in, -5, 5));
          (void)map->lookup(p);
          const auto keys = map->voxel_keys();
          if (keys.size() != map->size()) std::abort();
          break;
        }
      }
    } catch (const std::invalid_argument&) {
    }
  }
  return 0;
}
